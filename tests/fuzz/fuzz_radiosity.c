/* fuzz_radiosity.c - libFuzzer target for the radiosity solver behind the scene readers:
 * any scene the NFF reader accepts, or else the OBJ reader, is meshed and solved (an 8 x 8
 * hemicube, at most 16 shots) on 2x2x1 cells by two workers, and on one cell with
 * adaptive subdivision. Besides "never crash", it checks on both:
 *  - the mesher refuses only with a message (INPUT or LIMIT), never with a bad status;
 *  - the energy ledger balances: emitted = absorbed + unshot + escaped, to 1e-6;
 *  - every element's radiosity is finite and at least its emission (light only adds).
 * A mesh of more than 300 patches (or a scene that would make one: spheres and cones
 * are facets, 128 a sphere) is skipped: every shot visits every element, and the
 * fuzzer's inputs must stay fast (the ASan build is some 30 times slower). At 1000,
 * once spheres were meshed, the target ran 7-11 inputs a second (a replay of its
 * corpus: median 0.28 s an input); at 300, 500 (one or two spheres still solved).
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "radiosity/radiosity.h"
#include "vwalls/vwalls.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

enum { MAX_PATCHES = 300 };

static void die(const char *what, const char *detail)
{
    fprintf(stderr, "fuzz_radiosity: %s%s%s\n", what, detail ? ": " : "", detail ? detail : "");
    abort();
}

/* Solves scene s on layout dims with `workers` workers; subdivide > 0 refines. */
static void solve(const vw_scene *s, int dims[3], int workers, double subdivide)
{
    rad_options o;
    rad_options_init(&o);
    o.res = 8;
    o.max_shots = 16;
    o.per_round = 4;
    o.quiet = 1;
    o.workers = workers;
    o.subdivide = subdivide;
    o.max_level = 2;
    memcpy(o.dims, dims, sizeof o.dims);
    vw_box world = rad_world_box(s);
    vw_decomp *d = NULL;
    if (vw_decomp_create_grid(&world, o.dims, &d) != VW_OK) return; /* a box beyond doubles */
    char err[1024] = "";
    rad_mesh m;
    vw_status st = rad_mesh_build(s, "fuzz", d, &o, &m, err, sizeof err);
    if (st != VW_OK) {
        if (st != VW_E_INPUT && st != VW_E_LIMIT) die("the mesher failed", err);
        if (!err[0]) die("the mesher refused without a message", NULL);
        vw_decomp_free(d);
        return;
    }
    if (m.npieces > MAX_PATCHES) {
        rad_mesh_free(&m);
        vw_decomp_free(d);
        return;
    }
    rad_solver *sol = NULL;
    if (rad_solver_create(&m, d, &o, &sol, err, sizeof err) != VW_OK) die("create", err);
    int converged = 0;
    if (rad_solver_run(sol, NULL, NULL, &converged, err, sizeof err) != VW_OK) die("run", err);
    if (rad_solver_collect(sol, err, sizeof err) != VW_OK) die("collect", err);
    rad_ledger L = rad_solver_ledger(sol);
    if (!(L.error <= 1e-6)) {
        fprintf(stderr, "emitted %g absorbed %g unshot %g escaped %g (red)\n", L.emitted[0],
                L.absorbed[0], L.unshot[0], L.escaped[0]);
        die("the energy ledger does not balance", NULL);
    }
    size_t ne = 0;
    const rad_elem_result *e = rad_solver_elements(sol, &ne);
    for (size_t i = 0; i < ne; i++) {
        const rad_piece *pc = e[i].piece >= 0 && (size_t)e[i].piece < m.npieces ? &m.pieces[e[i].piece] : NULL;
        if (!pc) die("an element of no piece", NULL);
        for (int k = 0; k < 3; k++)
            if (!isfinite(e[i].B[k]) || e[i].B[k] < pc->emit[k] * (1 - 1e-9) - 1e-300)
                die("an element's radiosity is not finite or below its emission", NULL);
    }
    rad_solver_free(sol);
    rad_mesh_free(&m);
    vw_decomp_free(d);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char err[256];
    vw_scene *s = NULL;
    if (vw_scene_read_nff("fuzz.nff", (const char *)data, size, &s, err, sizeof err) != VW_OK &&
        vw_scene_read_obj("fuzz.obj", (const char *)data, size, NULL, &s, err, sizeof err) != VW_OK)
        return 0;
    /* Spheres and cones are meshed as facets: a scene that would be skipped below after
       meshing thousands of them (the ray tracer's sphereflakes in the corpus) is
       skipped now, or the target ran at 7 inputs a second. */
    if ((double)s->npolygons + rad_mesh_facets(s) > MAX_PATCHES) {
        vw_scene_free(s);
        return 0;
    }
    int grid[3] = {2, 2, 1}, one[3] = {1, 1, 1};
    solve(s, grid, 2, 0);
    solve(s, one, 1, 0.3);
    vw_scene_free(s);
    return 0;
}
