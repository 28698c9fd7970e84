/* vwalls/scene.h - the in-memory scene that the readers fill and the applications use.
 *
 * A scene is plain data: a camera, lights, materials and primitives (spheres, cones,
 * polygons over a shared vertex array). Every primitive carries a stable global id in
 * file order; ids are dense, 0..vw_scene_count_objects()-1, across all kinds, so that
 * an edit script or a stats line can name an object unambiguously.
 */
#ifndef VWALLS_SCENE_H
#define VWALLS_SCENE_H

#include <stddef.h>
#include <stdio.h>
#include "vwalls/common.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vw_material {
    float diffuse[3];   /* NFF: colour*Kd; MTL: Kd */
    float specular[3];  /* NFF: Ks,Ks,Ks; MTL: Ks. Weights the Phong highlight. */
    float reflect[3];   /* weights the mirror ray. NFF: Ks, Ks, Ks (its one Ks weights
                           highlight and mirror alike). MTL: Ks when illum asks for
                           ray-traced reflection (3 to 7) or no illum is given, else 0. */
    float shine;        /* Phong exponent (NFF Shine, MTL Ns) */
    float transmit;     /* NFF T; MTL 1-d or Tr */
    float ior;          /* index of refraction (NFF ior, MTL Ni); 1 when absent, and
                           for an MTL illum other than 6 or 7 (no refraction) */
    float emission[3];  /* MTL Ke, NFF '#vw Ke' after an 'f'; zero otherwise */
    /* Where the material was defined, so that a problem found after parsing (a
       reflectance the radiosity solver clamps) can be reported as file:line. These are
       not values: the fields above are the material, and neither vw_scene_fingerprint,
       the NFF writer nor NFF's sharing of equal materials looks past them. file and
       name are numbers of strings of the scene (vw_scene_string), 0 for none, so that a
       material stays plain data and a file's name is kept once however many materials
       it defines. A zeroed material has no place and no name. */
    int line;           /* MTL: its Kd line (the reflectance), else its newmtl; NFF: its
                           'f'; PLY (ASCII): the face record that gave its colour (its
                           own or its corners' mean); 0: none (a default material, a
                           generated scene, binary PLY data) */
    int file;           /* the file it was read from (MTL: the library's path as the
                           reader opened it; NFF, PLY: the name given to the reader);
                           0 for a default material and a generated scene */
    int name;           /* MTL: its newmtl (or usemtl) name; 0 in NFF and PLY */
} vw_material;

typedef struct vw_light {
    double pos[3];
    float color[3];     /* 1/sqrt(nlights) each where the file gave none */
} vw_light;

typedef struct vw_camera {
    double from[3], at[3], up[3];
    double angle;       /* full vertical field of view in degrees (NFF: angle) */
    double hither;      /* near distance */
    int width, height;  /* resolution */
    int valid;          /* 1 when the scene file gave a camera */
    int resolution_line; /* the file's line of 'resolution' (0: none), for messages */
} vw_camera;

typedef enum vw_prim_kind {
    VW_PRIM_SPHERE = 0,
    VW_PRIM_CONE = 1,       /* cone or cylinder, no caps (NFF c) */
    VW_PRIM_POLYGON = 2     /* planar polygon, >= 3 vertices (NFF p/pp, OBJ f) */
} vw_prim_kind;

/* An object's `line` is the line of the file that gave it (OBJ: its face's), so that a
   problem found after parsing can still be reported as file:line; 0 when it came from no
   file (vw_gen, a program). */
typedef struct vw_sphere {
    int id, material, line;
    double center[3], radius;      /* never 0; negative means "inside visible" (NFF) */
} vw_sphere;

typedef struct vw_cone {
    int id, material, line;
    double base[3], base_radius;   /* a negative radius means "inside visible" (NFF) */
    double apex[3], apex_radius;
} vw_cone;

typedef struct vw_polygon {
    int id, material, line;
    int first;        /* index into vw_scene.indices of the first vertex index */
    int count;        /* number of vertices, >= 3 */
    int has_normals;  /* 1 for NFF pp / OBJ with vn: normals[first..first+count) valid */
} vw_polygon;

typedef struct vw_scene {
    vw_camera camera;
    float background[3];
    vw_light *lights;       size_t nlights;
    vw_material *materials; size_t nmaterials;
    vw_sphere *spheres;     size_t nspheres;
    vw_cone *cones;         size_t ncones;
    vw_polygon *polygons;   size_t npolygons;
    double (*vertices)[3];  size_t nvertices;
    /* indices[k] is a vertex index; normals[k] (if present) the vertex normal for the
       same corner. Both have nindices entries; normals may be NULL when no polygon has
       normals. */
    int *indices;           size_t nindices;
    double (*normals)[3];
    /* The strings that materials' file and name number (strings[k - 1] is string k):
       each file's name once, however many materials it defines. The scene owns them
       (vw_scene_free frees them); a scene a program builds may leave them NULL and 0. */
    char **strings;         size_t nstrings;
} vw_scene;

/* Parsers. On failure they return VW_E_INPUT and write "file:line: message" into
   err (size errlen); *out is left NULL. The file name is used only for messages. */
VW_API vw_status vw_scene_read_file(const char *path, vw_scene **out, char *err, size_t errlen);
VW_API vw_status vw_scene_read_nff(const char *name, const char *text, size_t len,
                                   vw_scene **out, char *err, size_t errlen);
/* OBJ text; mtllib files are resolved relative to dir (may be NULL: none loaded, and
   usemtl names are then not checked). A library that cannot be read and a usemtl
   name no library defined are warnings, as in common OBJ tools: the faces get the
   default material (0.8 grey), and each missing library and each unknown name is
   reported once. An error inside a library that was read still fails the read. */
VW_API vw_status vw_scene_read_obj(const char *name, const char *text, size_t len,
                                   const char *dir, vw_scene **out, char *err, size_t errlen);

/* PLY (the Stanford format: ASCII, binary_little_endian or binary_big_endian): the
   element vertex (x, y, z; nx, ny, nz; red, green, blue) and the element face (the
   list vertex_indices or vertex_index; red, green, blue), every other element and
   property read past. A face's colour is its own, else the mean of its vertices',
   else 0.8 grey; no camera and no lights (the commands' defaults, as for OBJ). Binary
   data's errors name the line after end_header, and the element and record. */
VW_API vw_status vw_scene_read_ply(const char *name, const void *data, size_t len,
                                   vw_scene **out, char *err, size_t errlen);

/* Warnings: input the readers take with a fallback. Each is one line, "file:line:
   warning: message" (no newline), handed to fn(msg, user); the default (and fn NULL)
   prints it on stderr. The handler is process-wide: set it before reading, not while
   another thread reads. An MPI program whose processes all read the scene may pass a
   function that does nothing on all but one of them. */
typedef void (*vw_warning_fn)(const char *msg, void *user);
VW_API void vw_scene_set_warning_handler(vw_warning_fn fn, void *user);
VW_API void vw_scene_free(vw_scene *s);

/* Writers. The NFF written reads back to the same scene, bit for bit (numbers are
   printed with 17 significant digits). Two things NFF cannot say are handled so:
   a scene without a camera (OBJ) gets the vw_scene_default_camera() view, and
   per-channel specular colours, a mirror weight other than the specular colour (an
   MTL illum without reflection) and emission are written as extension comments,
       #vw Ks r g b        #vw Kr r g b        #vw Ke r g b
   right after the 'f' they belong to. Other NFF readers skip them as comments;
   ours applies them to the current material: #vw Ks sets the specular colour and
   the mirror weight (NFF's one Ks weights both), #vw Kr the mirror weight alone (so
   it follows any #vw Ks), #vw Ke the emission. Returns VW_E_IO if writing fails (f is
   flushed, so this includes what would otherwise wait in its buffer). */
VW_API vw_status vw_scene_write_nff(const vw_scene *s, FILE *f);
/* The same into a file, atomically: a failure leaves no file (nor a partial one). */
VW_API vw_status vw_scene_write_nff_file(const vw_scene *s, const char *path,
                                         char *err, size_t errlen);

/* Queries */
VW_API size_t vw_scene_count_objects(const vw_scene *s);
/* String k of the scene (a material's file or name), or NULL when k is 0 or not one of
   its strings. */
VW_API const char *vw_scene_string(const vw_scene *s, int k);
/* Text from a file shown in a message, on one line: the n bytes at s with every byte
   that is not printable ASCII, and the quote ' that delimits names, as '?'; at most
   max of them (0: no bound but out's), then "...". out holds outlen bytes (max + 4
   hold any name whole). Returns out. The readers, the radiosity solver and
   `vwalls info` show names and tokens so. */
#define VW_SHOWN_NAME 40 /* the bound messages keep names and tokens to */
VW_API const char *vw_text_shown(const char *s, size_t n, size_t max, char *out, size_t outlen);
/* A 64-bit hash (FNV-1a) of everything in the scene but its camera: objects, vertices
   and normals, materials (their values, not where they were defined), lights,
   background, value by value. The same file read by the
   same binary gives the same fingerprint; the commands compare it between MPI processes
   (the camera is compared with the command line's overrides, as the view). */
VW_API uint64_t vw_scene_fingerprint(const vw_scene *s);
/* Axis-aligned bounds of every primitive together (lights excluded). Spheres count
   as center +- r, cones as both end discs enclosed in boxes of half-size |r|, polygons
   by their vertices. An empty scene gives lo = hi = (0,0,0). */
VW_API void vw_scene_bounds(const vw_scene *s, double lo[3], double hi[3]);
/* Finds the primitive with global id `id`: its kind and its index in the array of
   that kind. VW_E_INVAL when there is no such id. O(log n). */
VW_API vw_status vw_scene_find_object(const vw_scene *s, int id, vw_prim_kind *kind,
                                      size_t *index);
/* Bounds of one primitive (same rules as vw_scene_bounds). */
VW_API void vw_scene_object_bounds(const vw_scene *s, vw_prim_kind kind, size_t index,
                                   double lo[3], double hi[3]);
/* Why the camera gives no view, or NULL when it gives one: a coordinate that is not a
   finite number, 'from' and 'at' the same point, or 'up' zero or parallel to the view
   direction. The NFF parser asks it of a 'v' block, the commands of their overrides. */
VW_API const char *vw_camera_problem(const vw_camera *cam);
/* The n - 2 triangles of a polygon with corners v[0..n), n >= 3, as corner numbers
   (0..n-1) into tri[0..n-2), each in the polygon's own winding. A convex polygon gets
   the fan (0, j, j+1); a concave one is ear-clipped in the plane of its Newell normal,
   so its triangles cover the polygon and nothing else. A polygon with no interior to
   keep (self-intersecting, or with no area) is fanned where clipping cannot go on.
   VW_E_INVAL for bad arguments, VW_E_NOMEM when its scratch memory (concave only)
   cannot be had. */
VW_API vw_status vw_polygon_triangulate(const double (*v)[3], int n, int (*tri)[3]);
/* Newell's normal of the polygon v[0..n) into out: its length is twice the polygon's
   area (of its projection, for one that is not planar), and it points to the side from
   which the corners run counterclockwise. Zero for n < 3 or no area. */
VW_API void vw_polygon_normal(const double (*v)[3], int n, double out[3]);
/* A camera that sees the whole scene: for scenes without one (OBJ). It looks at the
   centre of the bounds from the +z side, slightly above (+y up, the OBJ convention),
   with a 45 degree field of view; width and height are kept from *cam when positive,
   otherwise 512x512. cam->valid is set to 0 (it did not come from the file). */
VW_API void vw_scene_default_camera(const vw_scene *s, vw_camera *cam);

#ifdef __cplusplus
}
#endif
#endif
