/* vwalls/gen.h - scene generators: the SPD-style benchmark scenes (balls, rings,
 * tree), the paper's random-spheres load cases, the Cornell box and a furnished room.
 *
 * Generators are deterministic: the same name and parameters give the same scene,
 * bit for bit, on every machine (they use their own PRNG, never rand()).
 */
#ifndef VWALLS_GEN_H
#define VWALLS_GEN_H

#include <stddef.h>
#include <stdint.h>
#include "vwalls/common.h"
#include "vwalls/scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vw_gen_params {
    int size;          /* size factor / recursion depth; 0: the generator's default
                          (balls 4, rings 5, tree 6; cornell and room ignore it) */
    int count;         /* number of spheres for "spheres"; 0: 1000 */
    uint64_t seed;     /* PRNG seed (spheres, tree) */
    double cluster;    /* spheres: fraction placed in the cluster sub-region, 0..1 */
    int width, height; /* camera resolution; 0: 512 */
} vw_gen_params;

/* Zero size/count (generator defaults), seed 1, no clustering, 512x512. */
VW_API void vw_gen_params_init(vw_gen_params *p);

/* Builds the named scene. p may be NULL (defaults). VW_E_INVAL with a message in err
   for an unknown name or parameters out of range; VW_E_LIMIT when the spheres do not
   fit without overlapping. */
VW_API vw_status vw_gen(const char *name, const vw_gen_params *p, vw_scene **out,
                        char *err, size_t errlen);

/* The size a generator takes when vw_gen_params.size is 0: balls 4, rings 5, tree 6;
   0 for the others (and unknown names), which take no size. */
VW_API int vw_gen_default_size(const char *name);

/* The generator names, for help texts: i = 0, 1, ... until NULL. */
VW_API const char *vw_gen_name(size_t i);

#ifdef __cplusplus
}
#endif
#endif
