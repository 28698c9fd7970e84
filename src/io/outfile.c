/* src/io/outfile.c - vw_outfile: how every output file is written (vwalls/outfile.h),
 * complete or not at all, and the registry that lets a signal handler remove the
 * temporary files of a process being killed.
 *
 * The registry is a fixed array of slots, each a lock-free atomic state and a pointer to
 * the temporary name. Its invariant: a slot is LIVE exactly while its temporary file may
 * exist under that name and nobody but vw_outfile_remove_temps() may remove it. A writer
 * moves its slot through BUSY around each of the three system calls that make or end the
 * name (open with O_EXCL, rename, unlink), with every signal blocked on its own thread,
 * so the handler never runs on a thread whose slot is BUSY, and on any other thread it
 * waits for BUSY to end. The handler takes a slot from LIVE to GONE with one compare-
 * and-swap before it unlinks, and a writer leaves LIVE the same way, so exactly one of
 * them ends each temporary file, and a name is never unlinked after another process
 * could have taken it (a rename or unlink by the writer, then a new file by someone
 * else, then the handler's unlink). GONE is final: the process is ending.
 */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "io/io_internal.h"
#include "vwalls/outfile.h"

struct vw_outfile {
    FILE *f;      /* a stdio stream over fd whose writes keep their errno in werr */
    int fd;       /* -1 once closed */
    int werr;     /* errno of the first failed write or close, 0 none */
    char *path;   /* as given: every message names it */
    char *target; /* the regular file the temporary one replaces; NULL: written in place */
    char *tmp;    /* the temporary file, target.tmp.XXXXXX; NULL: written in place */
    int slot;     /* registry slot of tmp, -1 when not registered */
    struct vw_outfile *held_next; /* the held commits, in order (vw_outfile_hold) */
};

/* Commits held by vw_outfile_hold() until vw_outfile_release(), oldest first. */
static pthread_mutex_t held_mu = PTHREAD_MUTEX_INITIALIZER;
static int holding;
static struct vw_outfile *held_first, **held_last = &held_first;

/* ---- the registry ---------------------------------------------------------------- */

enum { SLOT_FREE, SLOT_BUSY, SLOT_LIVE, SLOT_GONE };
#define NSLOTS 64
/* The handler waits at most this long in all for writers in the middle of a call. */
#define WAIT_MS 2000

static struct {
    atomic_int state;
    _Atomic(const char *) tmp;
} slots[NSLOTS];
static atomic_int ending; /* set by vw_outfile_remove_temps(): no new temporary files */

/* Blocks every signal on the calling thread while a slot is BUSY. */
static void block_signals(sigset_t *old)
{
    sigset_t all;
    sigfillset(&all);
    pthread_sigmask(SIG_BLOCK, &all, old);
}

static void restore_signals(const sigset_t *old) { pthread_sigmask(SIG_SETMASK, old, NULL); }

/* A FREE slot made BUSY, -1 when all are taken (the file goes unregistered), -2 when
   the process is ending. Signals must be blocked. Claiming before reading `ending`
   (both sequentially consistent) means the handler, which sets `ending` before it
   scans, either sees this slot BUSY and waits for it, or is seen here. */
static int slot_claim(void)
{
    for (int i = 0; i < NSLOTS; i++) {
        int expect = SLOT_FREE;
        if (atomic_compare_exchange_strong(&slots[i].state, &expect, SLOT_BUSY)) {
            if (atomic_load(&ending)) {
                atomic_store(&slots[i].state, SLOT_FREE);
                return -2;
            }
            return i;
        }
    }
    return atomic_load(&ending) ? -2 : -1;
}

VW_API void vw_outfile_remove_temps(void)
{
    int saved = errno, waited = 0;
    atomic_store(&ending, 1);
    for (int i = 0; i < NSLOTS; i++) {
        for (;;) {
            int s = SLOT_LIVE;
            if (atomic_compare_exchange_strong(&slots[i].state, &s, SLOT_GONE)) {
                unlink(atomic_load(&slots[i].tmp));
                break;
            }
            if (s != SLOT_BUSY || waited >= WAIT_MS) break;
            poll(NULL, 0, 1); /* 1 ms; poll is async-signal-safe, nanosleep is not listed */
            waited++;
        }
    }
    errno = saved;
}

/* ---- the stream ------------------------------------------------------------------ */

/* stdio keeps no reason for a failed write (errno is overwritten by whatever runs next,
   and an fwrite larger than the buffer leaves nothing for fflush to retry), yet "No
   space left on device" is what the user must read. So the stream's writes go through
   this function, which keeps the first error. (fopencookie: glibc and musl.) */
static ssize_t stream_write(void *cookie, const char *buf, size_t n)
{
    vw_outfile *f = cookie;
    size_t done = 0;
    while (done < n) {
        ssize_t k = write(f->fd, buf + done, n - done);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            if (!f->werr)
                f->werr = k < 0 ? errno : EIO;
            return 0; /* the stream's error flag is set; commit reports werr */
        }
        done += (size_t)k;
    }
    return (ssize_t)n;
}

static int stream_close(void *cookie)
{
    vw_outfile *f = cookie;
    int r = close(f->fd);
    if (r != 0 && !f->werr)
        f->werr = errno;
    f->fd = -1;
    return r == 0 ? 0 : EOF;
}

/* The stream over f->fd; closes fd when it cannot be made. */
static vw_status open_stream(vw_outfile *f, char *err, size_t errlen)
{
    cookie_io_functions_t io = {NULL, stream_write, NULL, stream_close};
    f->f = fopencookie(f, "w", io);
    if (!f->f) {
        close(f->fd);
        f->fd = -1;
        vw__errf(err, errlen, "%s: out of memory", f->path);
        return VW_E_NOMEM;
    }
    return VW_OK;
}

/* ---- opening --------------------------------------------------------------------- */

static void outfile_free(vw_outfile *f)
{
    free(f->path);
    free(f->target);
    free(f->tmp);
    free(f);
}

/* Ends the temporary file: renamed over the target (put = 1) or removed. 0 done, -1
   the rename failed (errno says why; the temporary file is removed), 1 the handler
   took it (the process is ending; f->tmp must then stay allocated: the handler may be
   reading it on another thread). */
static int finish_temp(vw_outfile *f, int put)
{
    sigset_t old;
    block_signals(&old);
    int expect = SLOT_LIVE, r = 0, e = 0;
    if (f->slot >= 0 &&
        !atomic_compare_exchange_strong(&slots[f->slot].state, &expect, SLOT_BUSY)) {
        r = 1;
    } else {
        if (put && rename(f->tmp, f->target) != 0) {
            e = errno;
            r = -1;
        }
        if (!put || r)
            unlink(f->tmp);
        if (f->slot >= 0)
            atomic_store(&slots[f->slot].state, SLOT_FREE);
    }
    restore_signals(&old);
    errno = e;
    return r;
}

/* Creates target.tmp.XXXXXX with O_EXCL and mode 0666 (so the umask applies, unlike
   mkstemp's 0600) and registers it. The suffix mixes pid, time and a counter; EEXIST
   just tries another. */
static vw_status create_temp(vw_outfile *f, char *err, size_t errlen)
{
    size_t n = strlen(f->target);
    f->tmp = malloc(n + 16);
    if (!f->tmp) {
        vw__errf(err, errlen, "%s: out of memory", f->path);
        return VW_E_NOMEM;
    }
    static atomic_uint counter;
    uint64_t x = (uint64_t)getpid() * 0x9E3779B97F4A7C15ull ^ (uint64_t)time(NULL) ^
                 ((uint64_t)atomic_fetch_add(&counter, 1u) << 32);
    static const char alnum[] = "abcdefghijklmnopqrstuvwxyz0123456789";
    sigset_t old;
    block_signals(&old);
    f->slot = slot_claim();
    int fd = -1, e = EEXIST;
    for (int attempt = 0; f->slot != -2 && attempt < 100; attempt++) {
        x += 0x9E3779B97F4A7C15ull;
        uint64_t z = x;
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        z ^= z >> 31;
        char suffix[7];
        for (int i = 0; i < 6; i++) {
            suffix[i] = alnum[z % 36];
            z /= 36;
        }
        suffix[6] = '\0';
        snprintf(f->tmp, n + 16, "%s.tmp.%s", f->target, suffix);
        if (f->slot >= 0)
            atomic_store(&slots[f->slot].tmp, f->tmp);
        fd = open(f->tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        e = errno;
        if (fd >= 0 || e != EEXIST)
            break;
    }
    if (f->slot >= 0)
        atomic_store(&slots[f->slot].state, fd >= 0 ? SLOT_LIVE : SLOT_FREE);
    int ended = f->slot == -2;
    restore_signals(&old);
    if (ended) {
        vw__errf(err, errlen, "%s: not written: the process is ending", f->path);
        return VW_E_STATE;
    }
    if (fd < 0) {
        if (e == EEXIST)
            vw__errf(err, errlen, "%s: cannot create a temporary file", f->path);
        else
            vw__errf(err, errlen, "%s: cannot create: %s", f->path, strerror(e));
        return VW_E_IO;
    }
    f->fd = fd;
    vw_status st = open_stream(f, err, errlen);
    if (st != VW_OK && finish_temp(f, 0) == 1)
        f->tmp = NULL;
    return st;
}

/* Decides how path is written: f->target set (a regular file to replace, maybe new),
   or f->fd open on the existing non-regular file itself. */
static vw_status resolve(vw_outfile *f, char *err, size_t errlen)
{
    const char *path = f->path;
    int oom = 0;
    /* A name that is a device at lstat can be a regular file by the time it is opened:
       what was opened decides, and a regular file found so is decided afresh. */
    for (int tries = 0; tries < 4; tries++) {
        struct stat ls, st;
        if (lstat(path, &ls) != 0) {
            if (errno != ENOENT) {
                vw__errf(err, errlen, "%s: cannot write: %s", path, strerror(errno));
                return VW_E_IO;
            }
            oom = !(f->target = strdup(path)); /* a new file */
            break;
        }
        if (S_ISREG(ls.st_mode)) {
            oom = !(f->target = strdup(path));
            break;
        }
        st = ls;
        if (S_ISLNK(ls.st_mode)) {
            if (stat(path, &st) != 0) {
                if (errno == ENOENT) {
                    vw__errf(err, errlen, "%s: is a symbolic link to a file that does not "
                             "exist (create the file first, or remove the link)", path);
                } else {
                    vw__errf(err, errlen, "%s: cannot write: %s", path, strerror(errno));
                }
                return VW_E_IO;
            }
            if (S_ISREG(st.st_mode)) {
                f->target = realpath(path, NULL);
                if (!f->target) {
                    if ((oom = errno == ENOMEM))
                        break;
                    vw__errf(err, errlen, "%s: cannot follow the link: %s", path,
                             strerror(errno));
                    return VW_E_IO;
                }
                break;
            }
        }
        if (S_ISDIR(st.st_mode)) {
            vw__errf(err, errlen, "%s: cannot write: %s", path, strerror(EISDIR));
            return VW_E_IO;
        }
        /* A device, a FIFO or a socket: written in place. (A FIFO's open waits for a
           reader, as a shell's redirection does.) */
        int fd = open(path, O_WRONLY | O_NOCTTY | O_CLOEXEC);
        if (fd < 0) {
            vw__errf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
            return VW_E_IO;
        }
        struct stat fs;
        if (fstat(fd, &fs) == 0 && !S_ISREG(fs.st_mode)) {
            f->fd = fd;
            return VW_OK;
        }
        close(fd); /* nothing was written to it */
    }
    if (!f->target) {
        if (oom) {
            vw__errf(err, errlen, "%s: out of memory", path);
            return VW_E_NOMEM;
        }
        vw__errf(err, errlen, "%s: cannot write: the file changes kind while it is opened",
                 path);
        return VW_E_IO;
    }
    return VW_OK;
}

VW_API vw_status vw_outfile_open(const char *path, vw_outfile **out, char *err, size_t errlen)
{
    if (!out)
        return VW_E_INVAL;
    *out = NULL;
    if (!path || !*path) {
        vw__errf(err, errlen, "empty file name");
        return VW_E_INVAL;
    }
    if (atomic_load(&ending)) {
        vw__errf(err, errlen, "%s: not written: the process is ending", path);
        return VW_E_STATE;
    }
    vw_outfile *f = calloc(1, sizeof *f);
    if (!f || !(f->path = strdup(path))) {
        free(f);
        vw__errf(err, errlen, "%s: out of memory", path);
        return VW_E_NOMEM;
    }
    f->slot = -1;
    f->fd = -1;
    vw_status st = resolve(f, err, errlen);
    if (st == VW_OK)
        st = f->target ? create_temp(f, err, errlen) : open_stream(f, err, errlen);
    if (st != VW_OK) {
        outfile_free(f);
        return st;
    }
    *out = f;
    return VW_OK;
}

VW_API FILE *vw_outfile_stream(vw_outfile *f) { return f ? f->f : NULL; }

/* ---- ending ---------------------------------------------------------------------- */

VW_API vw_status vw_outfile_commit(vw_outfile *f, char *err, size_t errlen)
{
    if (!f)
        return VW_E_INVAL;
    int bad = ferror(f->f);
    bad |= fflush(f->f) != 0;
    bad |= fclose(f->f) != 0; /* closes fd */
    f->f = NULL;
    vw_status st = VW_OK;
    if (bad) {
        vw__errf(err, errlen, "%s: write failed: %s", f->path, strerror(f->werr ? f->werr : EIO));
        st = VW_E_IO;
    }
    if (f->tmp && !bad) {
        pthread_mutex_lock(&held_mu);
        int hold = holding;
        if (hold) {
            f->held_next = NULL;
            *held_last = f;
            held_last = &f->held_next;
        }
        pthread_mutex_unlock(&held_mu);
        if (hold)
            return VW_OK; /* complete, and put in place (or not) by vw_outfile_release */
    }
    if (f->tmp) {
        int r = finish_temp(f, !bad);
        if (r == 1) {
            f->tmp = NULL;
            if (!bad)
                vw__errf(err, errlen, "%s: not written: the process is ending", f->path);
            st = bad ? st : VW_E_STATE;
        } else if (r < 0) {
            vw__errf(err, errlen, "%s: cannot rename into place: %s", f->path,
                     strerror(errno));
            st = VW_E_IO;
        }
    }
    outfile_free(f);
    return st;
}

VW_API void vw_outfile_abort(vw_outfile *f)
{
    if (!f)
        return;
    if (f->f)
        fclose(f->f);
    if (f->tmp && finish_temp(f, 0) == 1)
        f->tmp = NULL;
    outfile_free(f);
}

VW_API void vw_outfile_hold(void)
{
    pthread_mutex_lock(&held_mu);
    holding = 1;
    pthread_mutex_unlock(&held_mu);
}

VW_API vw_status vw_outfile_release(int place, char *err, size_t errlen)
{
    pthread_mutex_lock(&held_mu);
    vw_outfile *f = held_first;
    held_first = NULL;
    held_last = &held_first;
    holding = 0;
    pthread_mutex_unlock(&held_mu);
    vw_status st = VW_OK;
    while (f) {
        vw_outfile *next = f->held_next;
        int put = place && st == VW_OK;
        int r = finish_temp(f, put);
        if (r == 1) { /* the signal handler removed it */
            f->tmp = NULL;
            if (put) {
                vw__errf(err, errlen, "%s: not written: the process is ending", f->path);
                st = VW_E_STATE;
            }
        } else if (r < 0) {
            vw__errf(err, errlen, "%s: cannot rename into place: %s", f->path, strerror(errno));
            st = VW_E_IO;
        }
        outfile_free(f);
        f = next;
    }
    return st;
}

VW_API vw_status vw_outfile_check(const char *path, char *err, size_t errlen)
{
    struct stat st;
    /* A device, a FIFO or a socket is written in place: not opened here (a FIFO's open
       would wait for a reader), only asked whether it may be. */
    if (path && *path && stat(path, &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode)) {
        if (access(path, W_OK) == 0)
            return VW_OK;
        vw__errf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return VW_E_IO;
    }
    vw_outfile *f;
    vw_status s = vw_outfile_open(path, &f, err, errlen);
    if (s == VW_OK)
        vw_outfile_abort(f);
    return s;
}

VW_API vw_status vw_outfile_write(const char *path, const void *buf, size_t len, char *err,
                                  size_t errlen)
{
    /* No bytes to write len of: refused before the file is touched (fwrite would have
       read from NULL, and the commit put a file of garbage or nothing in place). */
    if (!buf && len) {
        vw__errf(err, errlen, "%s: no data to write", path ? path : "(null)");
        return VW_E_INVAL;
    }
    vw_outfile *f;
    vw_status st = vw_outfile_open(path, &f, err, errlen);
    if (st != VW_OK)
        return st;
    if (len)
        fwrite(buf, 1, len, f->f); /* a failed write is the commit's to report */
    return vw_outfile_commit(f, err, errlen);
}
