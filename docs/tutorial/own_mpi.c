/* own_mpi.c - the tutorial's last step (docs/tutorial.md): vwalls inside a program that
 * owns MPI. The program initialises MPI itself, splits its processes into two groups,
 * and each group runs its own world on its own communicator (vw_config.mpi_comm).
 *   usage: mpirun -np P own_mpi      (built only when vwalls was built with MPI)
 */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>

#include "hello_module.h"

int main(int argc, char **argv)
{
    /* The library makes MPI calls from the thread that calls vw_world_run, so it needs
       at least MPI_THREAD_FUNNELED. It never initialises or finalises MPI it was given. */
    int level, rank, size;
    MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &level);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    int group = rank < size / 2 ? 0 : 1;
    MPI_Comm comm;
    MPI_Comm_split(MPI_COMM_WORLD, group, rank, &comm);

    /* Each group: the same points, its own layout of cells. */
    int dims[3] = {2 + group, 2, 2};
    vw_box unit = {{0, 0, 0}, {1, 1, 1}};
    vw_decomp *d = NULL;
    if (vw_decomp_create_grid(&unit, dims, &d) != VW_OK) MPI_Abort(MPI_COMM_WORLD, 1);
    int ncells = vw_decomp_cell_count(d);
    vw_config cfg;
    vw_config_init(&cfg);
    cfg.workers = 2;
    cfg.mpi_comm = &comm;           /* a pointer to the MPI_Comm, kept opaque in the API */

    /* What each rank prepares alone (here, memory) is agreed on before the world, on
       the group's communicator: a rank that gave up alone would leave the others
       waiting for it in vw_world_create. */
    enum { N = 20000 };
    ex_point *pts = malloc(sizeof *pts * N);
    ex_hello_result result = {ncells, calloc((size_t)ncells, sizeof(int64_t)),
                              calloc((size_t)ncells, sizeof(int64_t)), 0};
    char msg[256] = "";
    vw_status st = pts && result.own && result.neighbours ? VW_OK : VW_E_NOMEM;
    st = vw_config_agree(&cfg, st, msg, sizeof msg);
    /* A deterministic spread; some points lie exactly on walls, and the module's owner
       rule counts each of them once. */
    for (int i = 0; st == VW_OK && i < N; i++)
        for (int k = 0; k < 3; k++) pts[i].p[k] = ((i * (k + 7) * 7919) % 997 + 0.5) / 997.0;

    vw_world *w = NULL;
    if (st == VW_OK && (st = vw_world_create(&ex_hello_module, &result, d, &cfg, &w)) != VW_OK)
        snprintf(msg, sizeof msg, "%s", vw_world_errmsg(NULL)); /* (fails on every rank) */
    if (st == VW_OK) st = vw_world_add_objects(w, pts, N);
    if (st == VW_OK) st = vw_world_run(w);    /* run() commits first if needed */

    /* Agreement on the group's communicator: every rank learns if any rank failed. */
    if (w) {
        if (st != VW_OK) snprintf(msg, sizeof msg, "%s", vw_world_errmsg(w));
        st = vw_world_agree(w, st, msg, sizeof msg);
    }
    int rc = st != VW_OK;
    if (w && vw_world_is_output(w)) {
        int64_t total = 0;
        for (int c = 0; c < ncells; c++) total += result.own[c];
        int64_t counted = vw_world_counter(w, EX_HELLO_CNT_POINTS);
        if (rc == 0 && (total != N || counted != N || result.summaries != ncells)) {
            /* every point owned and counted once; every cell reports once */
            snprintf(msg, sizeof msg, "(points owned %lld, counted %lld, of %d; %lld reports "
                     "of %d cells)", (long long)total, (long long)counted, N,
                     (long long)result.summaries, ncells);
            rc = 1;
        }
        printf("group %d: %d process(es), %d cells, %lld points: %s%s\n", group,
               vw_world_processes(w), ncells, (long long)total, rc ? "FAILED " : "ok", msg);
    } else if (!w) {
        int grank;
        MPI_Comm_rank(comm, &grank);
        if (grank == 0) printf("group %d: FAILED %s\n", group, msg);
    }
    vw_world_free(w);
    vw_decomp_free(d);
    free(pts), free(result.own), free(result.neighbours);
    MPI_Comm_free(&comm);
    /* Every rank's status, so mpirun's exit status tells. */
    int any = 0;
    MPI_Allreduce(&rc, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    MPI_Finalize();
    return any;
}
