/* traffic.c - where the neighbour traffic went: the share of cell-to-cell messages and
 * bytes that stayed inside the sending worker, its process and its machine (processes
 * grouped per machine with MPI_Comm_split_type(MPI_COMM_TYPE_SHARED)). The figures a
 * mapping is judged by: a good mapping keeps most traffic off the network.
 */
#include "core/world_internal.h"
#include "vwalls/map.h"

#include <stdlib.h>
#include <string.h>

#if VW_HAVE_MPI
#include <mpi.h>
#include "transport/mpi_internal.h"
#endif

/* Both calls are collective under MPI: from a module's callback (a worker thread, in
   the middle of a run) they would meet the run's own collectives, so they are refused
   there as vw_world_agree is (world.h). */
vw_status vw_world_machines(vw_world *w, int *machine_of)
{
    if (!w) return VW_E_INVAL;
    vw__world_guard(w, "vw_world_machines");
    if (!machine_of)
        return vw__world_query_error(w, VW_E_INVAL, "vw_world_machines: machine_of is NULL");
    for (int p = 0; p < w->nprocs; p++) machine_of[p] = p;
#if VW_HAVE_MPI
    if (w->transport) {
        /* A machine is named by the lowest rank sharing memory with it. */
        MPI_Comm comm = vw__mpi_world_comm(w), shm;
        if (MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, w->rank, MPI_INFO_NULL, &shm) !=
            MPI_SUCCESS)
            return vw__world_query_error(w, VW_E_MPI, "vw_world_machines: "
                                         "MPI_Comm_split_type(MPI_COMM_TYPE_SHARED) failed");
        int leader = w->rank;
        MPI_Allreduce(MPI_IN_PLACE, &leader, 1, MPI_INT, MPI_MIN, shm);
        MPI_Comm_free(&shm);
        MPI_Allgather(&leader, 1, MPI_INT, machine_of, 1, MPI_INT, comm);
    }
#endif
    return VW_OK;
}

vw_status vw_world_traffic(vw_world *w, vw_traffic *out)
{
    if (!w) return VW_E_INVAL;
    vw__world_guard(w, "vw_world_traffic");
    if (!out) return vw__world_query_error(w, VW_E_INVAL, "vw_world_traffic: out is NULL");
    memset(out, 0, sizeof *out);
    int *mach = malloc(sizeof(int) * (size_t)w->nprocs);
    if (!mach)
        return vw__world_query_error(w, VW_E_NOMEM, "vw_world_traffic: out of memory for %d "
                                     "processes' machines", w->nprocs);
    vw_status st = vw_world_machines(w, mach); /* (which says why it failed) */
    if (st != VW_OK) {
        free(mach);
        return st;
    }
    uint64_t v[8] = {0};
    for (int i = 0; i < w->nworkers; i++) {
        const vw__worker *wk = &w->workers[i];
        v[2] += wk->tr_self_msgs;
        v[3] += wk->tr_self_bytes;
        for (int p = 0; p < w->nprocs; p++) {
            uint64_t m = wk->tr_proc[2 * p], b = wk->tr_proc[2 * p + 1];
            v[0] += m, v[1] += b;
            if (p == w->rank) v[4] += m, v[5] += b;
            if (mach[p] == mach[w->rank]) v[6] += m, v[7] += b;
        }
    }
    free(mach);
#if VW_HAVE_MPI
    if (w->transport)
        MPI_Allreduce(MPI_IN_PLACE, v, 8, MPI_UINT64_T, MPI_SUM, vw__mpi_world_comm(w));
#endif
    out->msgs = v[0], out->bytes = v[1];
    out->msgs_worker = v[2], out->bytes_worker = v[3];
    out->msgs_process = v[4], out->bytes_process = v[5];
    out->msgs_machine = v[6], out->bytes_machine = v[7];
    return VW_OK;
}
