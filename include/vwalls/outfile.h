/* vwalls/outfile.h - writing an output file so that it is complete or absent.
 *
 * Every file the library, the applications and the vwalls command write goes through
 * vw_outfile. What happens depends on what the name is when the file is opened:
 *  - nothing, or a regular file: the data goes to "path.tmp.XXXXXX" in the same
 *    directory, created with mode 0666 less the umask, and is renamed over path by
 *    vw_outfile_commit() only once all of it was written and closed without error;
 *    vw_outfile_abort(), a failed commit, or vw_outfile_remove_temps() in a signal
 *    handler removes the temporary file, so no failure leaves a partial file behind;
 *  - a symbolic link: it is followed, and the regular file it leads to is replaced as
 *    above (the temporary file goes next to that file), so the link stays a link. A
 *    link whose target does not exist is refused (VW_E_IO): creating files through
 *    dangling links is how links planted in shared directories redirect a program's
 *    output, so create the target first when that is what you want;
 *  - a device, a FIFO or a socket: it is opened and written in place, with no temporary
 *    file and no rename (writing to /dev/null leaves /dev/null a device; a write error,
 *    like /dev/full's "No space left on device", is reported by the commit);
 *  - a directory: refused (VW_E_IO, "Is a directory").
 * Errors come back as "path: reason" in err, path being the name as given. Under MPI
 * the caller decides which process writes (the output process, by the library's rule).
 *
 * The rename replaces whatever the name holds at commit time: the kind of the target
 * is decided at open, and a regular file swapped for something else meanwhile is
 * replaced all the same (no rename can be made conditional on what it replaces).
 */
#ifndef VWALLS_OUTFILE_H
#define VWALLS_OUTFILE_H

#include <stddef.h>
#include <stdio.h>
#include "vwalls/common.h"

#ifdef __cplusplus
extern "C" {
#endif

/* An output file being written. */
typedef struct vw_outfile vw_outfile;

/* Opens path for writing as described above and hands the file back in *out.
   VW_E_INVAL for an empty name, VW_E_NOMEM, VW_E_STATE once vw_outfile_remove_temps()
   has run (the process is ending), VW_E_IO for the rest; err gets "path: reason". */
VW_API vw_status vw_outfile_open(const char *path, vw_outfile **out, char *err,
                                 size_t errlen);
/* The stream to write to. Do not fclose it: commit or abort does. */
VW_API FILE *vw_outfile_stream(vw_outfile *f);
/* Flushes and closes the stream and, when everything was written, puts the file in
   place (rename). On any error (a write error of the stream included) the temporary
   file is removed, err gets "path: write failed: reason" or the like, and VW_E_IO comes
   back. Frees f in every case. */
VW_API vw_status vw_outfile_commit(vw_outfile *f, char *err, size_t errlen);
/* Closes the stream and removes the temporary file: nothing is written under path
   (a device or a FIFO keeps what was already sent to it). Frees f; NULL is a no-op. */
VW_API void vw_outfile_abort(vw_outfile *f);

/* Outputs that appear together or not at all. After vw_outfile_hold(), a commit that
   wrote everything keeps its temporary file (complete, closed, still removed by
   vw_outfile_remove_temps) and returns VW_OK; vw_outfile_release(1, ...) then renames
   every held file into place, in the order committed, and vw_outfile_release(0, ...)
   removes them all: a program holds before writing its outputs and releases with 1
   only when all were written (a full disk at the last one leaves none of them). A
   rename that fails (rare: the temporary file is in the target's directory) removes
   that file and the ones after it, returns VW_E_IO with "path: cannot rename into
   place: reason", and leaves the ones before it in place. Files written in place (a
   device, a FIFO) are not held. Process-wide, for the thread that writes the outputs;
   release ends the hold. */
VW_API void vw_outfile_hold(void);
VW_API vw_status vw_outfile_release(int place, char *err, size_t errlen);

/* Could path be written now, as vw_outfile_open would write it? For a new name, a
   regular file or a link to one, it makes the temporary file next to the target and
   removes it at once (so a link into a directory that cannot be written, a read-only
   file system or a dangling link fail here, with the message the open would give); a
   device, a FIFO or a socket is not opened, only checked for write permission. For a
   program that writes its outputs after long work: check them all first. */
VW_API vw_status vw_outfile_check(const char *path, char *err, size_t errlen);

/* The whole of buf[0..len) to path: open, write, commit. buf may be NULL only when len
   is 0 (VW_E_INVAL otherwise, and path is left as it was). */
VW_API vw_status vw_outfile_write(const char *path, const void *buf, size_t len, char *err,
                                  size_t errlen);

/* Removes every temporary file an open vw_outfile holds, for a handler of SIGINT,
   SIGTERM and the like before the process ends: async-signal-safe (lock-free atomics,
   unlink and poll only), and safe against every interleaving with the threads
   writing. A thread in the middle of creating, renaming or removing its
   temporary file (one system call, run with its signals blocked) is waited for, up to
   2 seconds. Afterwards the process is meant to end: vw_outfile_open fails with
   VW_E_STATE, and the commits and aborts of the files it removed fail or do nothing.
   The registry holds the temporary files of 64 vw_outfiles at once; one opened while
   64 others are open is written all the same, but is not registered (not removed by
   this function). */
VW_API void vw_outfile_remove_temps(void);

#ifdef __cplusplus
}
#endif
#endif
