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
   there as vw_world_agree is (world.h).

   And both end in agreement, as the steps of a world's life do (world.c's
   vw__world_step_agreed): a process that failed alone (a NULL pointer given to it only,
   no memory for the table of machines) and returned at once would leave the others
   waiting for it in the call's collectives, and go on to meet them in the wrong ones.
   So every process makes the same collectives whatever failed on it, agrees, and only
   then makes those that need what failed (machine_of, the figures); a failure is the
   lowest failing process's status on every process, its message "rank R: ..." in each
   one's vw_world_errmsg (replacing this process's own, as a query's message replaces
   an older one: vw__world_query_error). On the threads engine a call fails as it
   failed. */
#if VW_HAVE_MPI
static vw_status query_agreed(vw_world *w, vw_status st)
{
    char msg[512] = "";
    if (st != VW_OK) snprintf(msg, sizeof msg, "%s", vw_world_errmsg(w));
    vw_status all = vw__world_agree(w, st, msg, sizeof msg);
    return all == VW_OK ? VW_OK : vw__world_query_error(w, all, "%s", msg);
}
#endif

/* The machines of the world's processes into machine_of, ending in agreement with st,
   this process's outcome so far (machine_of may be NULL only when st says a failure).
   `call` names the public call in a message. */
static vw_status machines_agreed(vw_world *w, vw_status st, int *machine_of, const char *call)
{
    if (st == VW_OK)
        for (int p = 0; p < w->nprocs; p++) machine_of[p] = p;
#if VW_HAVE_MPI
    if (w->transport) {
        /* A machine is named by the lowest rank sharing memory with it: rank 0 of the
           group split off with the world's ranks as keys, looked up locally. No
           collective is made on that group, so a failure here has only the world's
           agreement below to meet. */
        MPI_Comm comm = vw__mpi_world_comm(w), shm;
        int leader = w->rank;
        if (MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, w->rank, MPI_INFO_NULL, &shm) ==
            MPI_SUCCESS) {
            MPI_Group g_shm, g_world;
            int first = 0;
            MPI_Comm_group(shm, &g_shm);
            MPI_Comm_group(comm, &g_world);
            MPI_Group_translate_ranks(g_shm, 1, &first, g_world, &leader);
            MPI_Group_free(&g_shm);
            MPI_Group_free(&g_world);
            MPI_Comm_free(&shm);
        } else if (st == VW_OK) {
            st = vw__world_query_error(w, VW_E_MPI, "%s: MPI_Comm_split_type("
                                       "MPI_COMM_TYPE_SHARED) failed", call);
        }
        st = query_agreed(w, st);
        if (st == VW_OK) MPI_Allgather(&leader, 1, MPI_INT, machine_of, 1, MPI_INT, comm);
        return st;
    }
#else
    (void)call;
#endif
    return st;
}

vw_status vw_world_machines(vw_world *w, int *machine_of)
{
    if (!w) return VW_E_INVAL;
    vw__world_guard(w, "vw_world_machines");
    vw_status st = VW_OK;
    if (!machine_of)
        st = vw__world_query_error(w, VW_E_INVAL, "vw_world_machines: machine_of is NULL");
    return machines_agreed(w, st, machine_of, "vw_world_machines");
}

vw_status vw_world_traffic(vw_world *w, vw_traffic *out)
{
    if (!w) return VW_E_INVAL;
    vw__world_guard(w, "vw_world_traffic");
    vw_status st = VW_OK;
    int *mach = NULL;
    if (!out) {
        st = vw__world_query_error(w, VW_E_INVAL, "vw_world_traffic: out is NULL");
    } else {
        memset(out, 0, sizeof *out);
        mach = malloc(sizeof(int) * (size_t)w->nprocs);
        if (!mach)
            st = vw__world_query_error(w, VW_E_NOMEM, "vw_world_traffic: out of memory for "
                                       "%d processes' machines", w->nprocs);
    }
    /* Past this agreement every process goes on, or none does. */
    st = machines_agreed(w, st, mach, "vw_world_traffic");
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
