/* mpi_internal.h - what the two MPI files share: the launcher test, library-side
 * initialisation and the world's communicator. Only included when built with MPI.
 */
#ifndef VW_MPI_INTERNAL_H
#define VW_MPI_INTERNAL_H

#include <mpi.h>

#include "core/world_internal.h"

/* The engine's thread level: workers make no MPI calls; only the thread that calls
   vw_world_run (and the collective calls between runs) does. */
#define VW__MPI_THREAD_LEVEL MPI_THREAD_FUNNELED

/* Was the process started by an MPI launcher (looks at the environment only)? */
int vw__mpi_launcher_env(void);
/* Initialises MPI for a library user who did not (finalised at exit). */
vw_status vw__mpi_autoinit(char *msg, size_t len);
/* Agreement on a communicator (see vw_engine_agree). */
vw_status vw__mpi_agree(MPI_Comm comm, vw_status local, char *msg, size_t len);
/* This process's share of its host's cores, given the cores it may run on (vw_host_cores):
   cores * U / S, at least 1, where among the processes of comm on this host
   (MPI_COMM_TYPE_SHARED) S sums the CPUs each may run on (affinity) and U counts the CPUs
   any may run on. Processes bound to CPUs of their own (Open MPI's --bind-to core) keep
   their cores; k processes that may each run on every CPU (unbound, oversubscribed, or
   bound to one socket they share) get a k-th each. VW_CORES's count is kept as it is.
   Collective on comm. */
int vw__mpi_core_share(MPI_Comm comm, int cores);
/* The world's communicator, or MPI_COMM_NULL for the threads engine. */
MPI_Comm vw__mpi_world_comm(const vw_world *w);

#endif
