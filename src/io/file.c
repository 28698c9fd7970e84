/* src/io/file.c - whole-file reading and atomic file writing for the io module.
 *
 * Atomic writes go to "path.tmp.XXXXXX" next to the target and are renamed over it
 * only once everything was written and closed without error, so a reader of path
 * sees either the old file or the complete new one, and a failure leaves nothing.
 */
#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "io/io_internal.h"

vw_status vw__read_whole_file(const char *path, char **text, size_t *len, char *err,
                              size_t errlen)
{
    *text = NULL;
    *len = 0;
    FILE *f = fopen(path, "rb");
    if (!f) {
        vw__errf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return VW_E_INPUT;
    }
    struct stat st;
    if (fstat(fileno(f), &st) == 0 && S_ISDIR(st.st_mode)) {
        fclose(f);
        vw__errf(err, errlen, "%s: cannot open: %s", path, strerror(EISDIR));
        return VW_E_INPUT;
    }
    size_t cap = 65536, n = 0;
    char *buf = malloc(cap);
    if (!buf) {
        fclose(f);
        vw__errf(err, errlen, "%s: out of memory", path);
        return VW_E_NOMEM;
    }
    /* Read in growing chunks rather than trusting the size from stat: pipes and
       /proc files report 0. */
    for (;;) {
        if (cap - n < 2) {
            if (cap > SIZE_MAX / 2) {
                free(buf);
                fclose(f);
                vw__errf(err, errlen, "%s: file too large", path);
                return VW_E_LIMIT;
            }
            char *q = realloc(buf, cap * 2);
            if (!q) {
                free(buf);
                fclose(f);
                vw__errf(err, errlen, "%s: out of memory", path);
                return VW_E_NOMEM;
            }
            buf = q;
            cap *= 2;
        }
        size_t got = fread(buf + n, 1, cap - n - 1, f);
        n += got;
        if (got == 0)
            break;
    }
    if (ferror(f)) {
        int e = errno;
        free(buf);
        fclose(f);
        vw__errf(err, errlen, "%s: read error: %s", path, strerror(e));
        return VW_E_IO;
    }
    fclose(f);
    buf[n] = '\0';
    *text = buf;
    *len = n;
    return VW_OK;
}

vw_status vw__atomic_open(vw__atomic_file *af, const char *path, char *err, size_t errlen)
{
    memset(af, 0, sizeof *af);
    size_t n = strlen(path);
    af->path = malloc(n + 1);
    af->tmp = malloc(n + 16);
    if (!af->path || !af->tmp) {
        free(af->path);
        free(af->tmp);
        vw__errf(err, errlen, "%s: out of memory", path);
        return VW_E_NOMEM;
    }
    memcpy(af->path, path, n + 1);
    /* mkstemp would create the file with mode 0600; opening with O_EXCL and 0666
       gives the same race-free creation with the permissions the user's umask asks
       for. The suffix mixes pid, time and a counter; EEXIST just tries another. */
    static unsigned counter;
    uint64_t x = (uint64_t)getpid() * 0x9E3779B97F4A7C15ull ^ (uint64_t)time(NULL) ^
                 ((uint64_t)__atomic_fetch_add(&counter, 1u, __ATOMIC_RELAXED) << 32);
    static const char alnum[] = "abcdefghijklmnopqrstuvwxyz0123456789";
    int reported = 0;
    for (int attempt = 0; attempt < 100; attempt++) {
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
        snprintf(af->tmp, n + 16, "%s.tmp.%s", path, suffix);
        int fd = open(af->tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (fd < 0) {
            if (errno == EEXIST)
                continue;
            vw__errf(err, errlen, "%s: cannot create: %s", path, strerror(errno));
            reported = 1;
            break;
        }
        af->f = fdopen(fd, "wb");
        if (!af->f) {
            vw__errf(err, errlen, "%s: cannot create: %s", path, strerror(errno));
            close(fd);
            unlink(af->tmp);
            reported = 1;
            break;
        }
        return VW_OK;
    }
    if (!reported)
        vw__errf(err, errlen, "%s: cannot create a temporary file", path);
    free(af->path);
    free(af->tmp);
    memset(af, 0, sizeof *af);
    return VW_E_IO;
}

vw_status vw__atomic_commit(vw__atomic_file *af, char *err, size_t errlen)
{
    vw_status st = VW_OK;
    int bad = ferror(af->f);
    int e = errno;
    if (fflush(af->f) != 0) {
        bad = 1;
        e = errno;
    }
    if (fclose(af->f) != 0 && !bad) {
        bad = 1;
        e = errno;
    }
    af->f = NULL;
    if (bad) {
        vw__errf(err, errlen, "%s: write failed: %s", af->path, strerror(e));
        unlink(af->tmp);
        st = VW_E_IO;
    } else if (rename(af->tmp, af->path) != 0) {
        vw__errf(err, errlen, "%s: cannot rename into place: %s", af->path,
                 strerror(errno));
        unlink(af->tmp);
        st = VW_E_IO;
    }
    free(af->path);
    free(af->tmp);
    memset(af, 0, sizeof *af);
    return st;
}

void vw__atomic_abort(vw__atomic_file *af)
{
    if (af->f) {
        fclose(af->f);
        unlink(af->tmp);
    }
    free(af->path);
    free(af->tmp);
    memset(af, 0, sizeof *af);
}
