/* src/io/file.c - whole-file reading for the io module's readers. (Writing is
 * vw_outfile, src/io/outfile.c.)
 */
#include <errno.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

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
