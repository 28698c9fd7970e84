/* cli.c - what every vwalls subcommand shares: option values, messages, engine set-up
 * and the progress bar.
 */
#include "cli.h"
#include "vwalls/engine.h"

#include <errno.h>
#include <sys/stat.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <time.h>
#include <unistd.h>

static int cli_rank = 0;

int vw_cli_is_output(void) { return cli_rank == 0; }

int vw_cli_fault(const char *name) { return vw_test_fault(name); }

int vw_cli_job_workers(long workers)
{
    return vw_engine_workers((int)workers) * vw_engine_size();
}

void vw_cli_error(const char *cmd, const char *fmt, ...)
{
    if (!vw_cli_is_output()) return;
    /* The line in one write: a launcher that merges the processes' streams (MPICH's
       Hydra) put another stream's output between the pieces of a line written in three. */
    char msg[8192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    fprintf(stderr, "vwalls %s: %s\n", cmd, msg);
}

int vw_cli_int(const char *cmd, const char *opt, const char *s, long lo, long hi, long *out)
{
    char *end;
    errno = 0;
    long v = strtol(s ? s : "", &end, 10);
    /* strtol also skips white space and takes a '+': " 3" and "+3" were a number here
       and not in --seed or --cells. Digits, after a '-' for a negative number. */
    const char *d = s && *s == '-' ? s + 1 : s;
    if (!s || !(*d >= '0' && *d <= '9') || *end || errno || v < lo || v > hi) {
        vw_cli_error(cmd, "%s: bad value '%s' (expected a whole number from %ld to %ld)", opt,
                     s ? s : "", lo, hi);
        return -1;
    }
    *out = v;
    return 0;
}

double vw_cli_strtod(const char *s, char **end)
{
    /* Decimal notation only, and no white space or '+' before it, as in whole numbers:
       strtod also read C99's hexadecimal floats (--angle 0x10 was 16 degrees). */
    double v = vw_strtod_decimal(s, end, 0);
    if (errno == ERANGE && fabs(v) <= DBL_MIN) errno = 0;
    return v;
}

int vw_cli_double(const char *cmd, const char *opt, const char *s, double lo, double hi, double *out)
{
    char *end;
    double v = vw_cli_strtod(s ? s : "", &end);
    if (!s || !*s || *end || errno || !isfinite(v) || v < lo || v > hi) {
        vw_cli_error(cmd, "%s: bad value '%s' (expected a number from %g to %g)", opt, s ? s : "",
                     lo, hi);
        return -1;
    }
    *out = v;
    return 0;
}

int vw_cli_fov_ok(double deg)
{
    return deg > 0 && deg < 180;
}

int vw_cli_angle(const char *cmd, const char *opt, const char *s, double *out)
{
    char *end;
    double v = vw_cli_strtod(s ? s : "", &end);
    if (!s || !*s || *end || errno || !vw_cli_fov_ok(v)) {
        vw_cli_error(cmd, "%s: bad value '%s' (expected degrees above 0 and below 180)", opt,
                     s ? s : "");
        return -1;
    }
    *out = v;
    return 0;
}

int vw_cli_numbers(const char *cmd, const char *opt, const char *s, const char *shape,
                   double *out, int min, int max, int *n)
{
    int k = 0;
    const char *p = s ? s : "";
    for (;;) {
        char *end;
        double v = vw_cli_strtod(p, &end);
        if (end == p || errno || !(fabs(v) <= FLT_MAX) || k == max) break;
        out[k++] = v;
        if (!*end) {
            if (k < min) break;
            if (n) *n = k;
            return 0;
        }
        if (*end != ',') break;
        p = end + 1;
    }
    vw_cli_error(cmd, "%s: bad value '%s' (expected %s: finite numbers of at most %g in size)",
                 opt, s ? s : "", shape, (double)FLT_MAX);
    return -1;
}

int vw_cli_box(const char *cmd, const char *opt, const char *s, vw_box *out)
{
    double b[6];
    if (vw_cli_numbers(cmd, opt, s, "X0,Y0,Z0,X1,Y1,Z1", b, 6, 6, NULL)) return -1;
    for (int k = 0; k < 3; k++) {
        if (!(b[k] < b[k + 3])) {
            vw_cli_error(cmd, "%s: bad value '%s' (the box's low corner must lie below its "
                              "high corner on every axis)", opt, s);
            return -1;
        }
        out->lo[k] = b[k];
        out->hi[k] = b[k + 3];
    }
    return 0;
}

int vw_cli_size(const char *cmd, const char *opt, const char *s, int *w, int *h)
{
    long a, b;
    char *end;
    errno = 0;
    a = strtol(s ? s : "", &end, 10);
    /* Digits on both sides of the x (strtol also took " 8x 8" and "+8x+8"). */
    if (s && *s >= '0' && *s <= '9' && (*end == 'x' || *end == 'X') && !errno) {
        const char *q = end + 1;
        b = strtol(q, &end, 10);
        /* The ray tracer's limit (rt_job_create), for every command: a size it accepts
           here and refuses later told the user two different maxima. */
        if (*q >= '0' && *q <= '9' && !*end && !errno && a >= 1 && b >= 1 && a <= 16384 &&
            b <= 16384) {
            *w = (int)a;
            *h = (int)b;
            return 0;
        }
    }
    vw_cli_error(cmd, "%s: bad value '%s' (expected WIDTHxHEIGHT, like 512x512: sides of 1 to "
                      "16384)", opt, s ? s : "");
    return -1;
}

int vw_cli_frame_pattern(const char *cmd, const char *opt, const char *s)
{
    int conversions = 0, ok = 1;
    for (const char *p = s; *p; p++) {
        if (*p != '%') continue;
        if (p[1] == '%') {
            p++;
            continue;
        }
        p++;
        while (*p && strchr("0-+ #", *p)) p++;
        int digits = 0;
        while (*p >= '0' && *p <= '9') p++, digits++;
        if (*p == '.') {
            int prec = 0;
            for (p++; *p >= '0' && *p <= '9'; p++) prec++;
            if (prec > 2) digits = 3;
        }
        if (digits > 2 || (*p != 'd' && *p != 'i')) {
            ok = 0;
            break;
        }
        conversions++;
    }
    if (ok && conversions == 1 && vw_image_format_of(s) == VW_IMAGE_PNG) return 0;
    vw_cli_error(cmd, "%s: bad pattern '%s' (expected a .png name with one %%d for the frame "
                      "number, like 'frames/%%04d.png'; %%%% for a percent sign)", opt, s);
    return -1;
}

int vw_cli_layout(const char *cmd, const char *opt, const char *s, int dims[3])
{
    char err[256];
    if (vw_layout_parse(s, dims, err, sizeof err) != VW_OK) {
        vw_cli_error(cmd, "%s: %s", opt, err);
        return -1;
    }
    return 0;
}

const char *vw_cli_value(const char *cmd, int argc, char **argv, int *i)
{
    if (*i + 1 >= argc) {
        vw_cli_error(cmd, "%s needs a value", argv[*i]);
        return NULL;
    }
    /* "--stats --quiet" or "--stats -q" forgot the value: writing a file named --quiet
       would hide it. (A value may start with one '-': a negative number.) -o, -q and
       -h are every short option of every command. */
    const char *v = argv[*i + 1];
    if ((v[0] == '-' && v[1] == '-' && v[2]) || !strcmp(v, "-o") || !strcmp(v, "-q") ||
        !strcmp(v, "-h")) {
        vw_cli_error(cmd, "%s needs a value, not the option '%s'", argv[*i], v);
        return NULL;
    }
    return argv[++*i];
}

int vw_cli_image_option(const char *cmd, int argc, char **argv, int *i, int *width, int *height,
                        long *depth)
{
    const char *a = argv[*i], *v;
    if (strcmp(a, "--size") && strcmp(a, "--depth")) return 0;
    if (!(v = vw_cli_value(cmd, argc, argv, i))) return -1;
    if (!strcmp(a, "--size")) return vw_cli_size(cmd, a, v, width, height) ? -1 : 1;
    return vw_cli_int(cmd, a, v, 1, 64, depth) ? -1 : 1;
}

int vw_cli_scene_arg(const char *cmd, const char *a, const char **scene)
{
    if (a[0] == '-' && a[1]) {
        vw_cli_error(cmd, "unknown option '%s' (try --help)", a);
        return -1;
    }
    if (*scene) {
        vw_cli_error(cmd, "more than one scene: '%s' and '%s'", *scene, a);
        return -1;
    }
    *scene = a;
    return 0;
}

const char *vw_cli_output(const char *cmd, int argc, char **argv, int *i)
{
    const char *v = vw_cli_value(cmd, argc, argv, i);
    if (v && !*v) {
        vw_cli_error(cmd, "%s: empty file name", argv[*i - 1]);
        return NULL;
    }
    /* Not standard output: the outputs are written whole, then renamed into place, and
       "-" made a file of that name. /dev/stdout writes there. */
    if (v && !strcmp(v, "-")) {
        vw_cli_error(cmd, "%s -: standard output is not an output here (name a file, or "
                          "/dev/stdout)", argv[*i - 1]);
        return NULL;
    }
    return v;
}

int vw_cli_named(const char *cmd, const char *opt, const char *path)
{
    const char *slash = strrchr(path, '/'), *base = slash ? slash + 1 : path;
    if (base[0] != '.' || !base[1] || strchr(base + 1, '.')) return 0;
    vw_cli_error(cmd, "%s %s: no file name before the ending '%s' (the file would be hidden "
                      "and nameless, like x%s without the x)", opt, path, base, base);
    return -1;
}

int vw_cli_scene_output(const char *cmd, const char *opt, const char *path, const char *ext,
                        const char *format)
{
    size_t n = strlen(path), m = strlen(ext);
    struct stat sb;
    if (vw_cli_named(cmd, opt, path)) return -1;
    if ((n > m && !strcasecmp(path + n - m, ext)) || (stat(path, &sb) == 0 && !S_ISREG(sb.st_mode)))
        return 0;
    vw_cli_error(cmd, "%s %s: written as %s, which vwalls reads only from a name ending in %s",
                 opt, path, format, ext);
    return -1;
}

int vw_cli_scene_size(const char *path, const vw_camera *cam, int width)
{
    if (width > 0 || (cam->width <= 16384 && cam->height <= 16384)) return 0;
    char where[64] = "";
    if (cam->resolution_line > 0) snprintf(where, sizeof where, ":%d", cam->resolution_line);
    if (vw_cli_is_output())
        fprintf(stderr, "%s%s: resolution %dx%d too large for the ray tracer (at most 16384 on "
                        "a side): give --size WxH to draw another size\n", path, where,
                cam->width, cam->height);
    return -1;
}

double vw_cli_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

const char *vw_cli_bytes(double n, char *buf, size_t len)
{
    if (n >= 1e9)
        snprintf(buf, len, "%.2f GB", n / 1e9);
    else if (n >= 1e6)
        snprintf(buf, len, "%.0f MB", n / 1e6);
    else
        snprintf(buf, len, "%.0f kB", n / 1e3);
    return buf;
}

const char *vw_cli_crowding(int workers, double cores, char *buf, size_t len)
{
    char c[32];
    if (cores < 1)
        snprintf(c, sizeof c, "%.2g of a core", cores);
    else
        snprintf(c, sizeof c, "%.3g core%s", cores, cores == 1 ? "" : "s");
    snprintf(buf, len, "%d worker%s on %s%s", workers, workers == 1 ? "" : "s", c,
             vw_engine_size() > 1 ? " in each process" : "");
    return buf;
}

int vw_cli_local_processes(void)
{
    /* Open MPI and MPICH's launcher (Hydra) say how many processes share this host. */
    const char *names[] = {"OMPI_COMM_WORLD_LOCAL_SIZE", "MPI_LOCALNRANKS"};
    for (int i = 0; i < 2; i++) {
        const char *v = getenv(names[i]);
        long n = v ? strtol(v, NULL, 10) : 0;
        if (n >= 1 && n <= 1 << 20) return (int)n;
    }
    return 1;
}

static void ignore_warning(const char *msg, void *user) { (void)msg, (void)user; }

/* MPI only when a launcher started us (the library decides: vw_engine_init does nothing
   otherwise), so a plain run of the binary is exactly the threads engine. */
void vw_cli_engine_init(int *argc, char ***argv)
{
    char msg[400];
    if (vw_engine_init(argc, argv, msg, sizeof msg) != VW_OK) {
        fprintf(stderr, "vwalls: rank %d: %s\n", vw_engine_rank(), msg);
        vw_engine_abort(VW_EXIT_FAIL, NULL);
    }
    cli_rank = vw_engine_rank();
    /* Every process reads the scene; the output process alone warns about it. */
    if (cli_rank != 0) vw_scene_set_warning_handler(ignore_warning, NULL);
}

void vw_cli_engine_finish(void) { vw_engine_finish(); }

/* vw_engine_agree on an exit status: the agreement carries a status, not a number, so
   the two kinds of failure map onto two statuses and back. */
static int agree_exit(int rc, char *msg, size_t len)
{
    vw_status all = vw_engine_agree(rc == VW_EXIT_OK      ? VW_OK
                                    : rc == VW_EXIT_USAGE ? VW_E_INPUT
                                                          : VW_E_IO,
                                    msg, len);
    return all == VW_OK ? VW_EXIT_OK : all == VW_E_INPUT ? VW_EXIT_USAGE : VW_EXIT_FAIL;
}

int vw_cli_job_status(const char *cmd, int rc)
{
    if (vw_engine_size() == 1) return rc;
    char msg[256];
    snprintf(msg, sizeof msg, "failed with exit status %d", rc);
    int all = agree_exit(rc, msg, sizeof msg);
    if (all != VW_EXIT_OK && rc == VW_EXIT_OK && vw_cli_is_output())
        fprintf(stderr, "vwalls%s%s: %s\n", cmd ? " " : "", cmd ? cmd : "", msg);
    return all;
}

int vw_cli_fail(const char *cmd, int rc, char *msg, size_t len, const char *fmt, ...)
{
    int k = snprintf(msg, len, "vwalls %s: ", cmd);
    if (k >= 0 && (size_t)k < len) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg + k, len - (size_t)k, fmt, ap);
        va_end(ap);
    }
    return rc;
}

int vw_cli_agree(const char *cmd, int rc, char *msg, size_t len)
{
    int all = agree_exit(rc, msg, len);
    if (all == VW_EXIT_OK) return VW_EXIT_OK;
    if (vw_cli_is_output() && len && *msg) {
        /* "rank R: vwalls CMD: what" becomes "vwalls CMD: rank R: what", the order of
           every other message naming a rank. */
        char pre[64];
        int n = snprintf(pre, sizeof pre, "vwalls %s: ", cmd);
        const char *colon = strstr(msg, ": ");
        if (!strncmp(msg, "rank ", 5) && colon && n > 0 && (size_t)n < sizeof pre &&
            !strncmp(colon + 2, pre, (size_t)n))
            fprintf(stderr, "%s%.*s%s\n", pre, (int)(colon + 2 - msg), msg, colon + 2 + n);
        else
            fprintf(stderr, "%s\n", msg);
    }
    return all;
}

/* Can a file be made at path: its directory exists and may be written into, and path
   is not a directory? 0, or -1 with the reason in err (vw_cli_check_outputs). */
static int check_writable(const char *opt, const char *path, char *err, size_t errlen)
{
    struct stat st;
    if (stat(path, &st) == 0 && S_ISDIR(st.st_mode)) {
        snprintf(err, errlen, "%s %s: cannot write: it is a directory", opt, path);
        return -1;
    }
    const char *slash = strrchr(path, '/');
    char *dir = slash ? strndup(path, slash == path ? 1 : (size_t)(slash - path)) : strdup(".");
    if (!dir) {
        snprintf(err, errlen, "out of memory");
        return -1;
    }
    int bad = 0;
    if (stat(dir, &st) != 0) bad = errno;
    else if (!S_ISDIR(st.st_mode)) bad = ENOTDIR;
    else if (access(dir, W_OK | X_OK) != 0) bad = errno;
    if (bad) snprintf(err, errlen, "%s %s: cannot write: %s: %s", opt, path, dir, strerror(bad));
    free(dir);
    if (bad) return -1;
    /* The rest as the write itself will meet it: a link followed into a directory that
       cannot be written, a dangling link, a read-only file system. */
    char why[768];
    if (vw_outfile_check(path, why, sizeof why) == VW_OK) return 0;
    snprintf(err, errlen, "%s %s", opt, why);
    return -1;
}

/* Which file a name stands for: an existing file by its device and inode (a hard
   link, a symbolic link, "./x" and "x" are one file), a new one by its directory's
   resolved path and its own name. A device or a FIFO (/dev/null, /dev/stdout) is
   nobody's data: exempt (0). 1 when *id is filled in, 0 also when out of memory. */
typedef struct file_id {
    dev_t dev;
    ino_t ino;
    char *path; /* a new file's resolved name, malloc'ed; NULL for an existing one */
} file_id;

static int file_identify(const char *name, file_id *id)
{
    struct stat st;
    id->path = NULL;
    /* /dev/stdout leads to whatever standard output is, a file too: named twice, it is
       the user's choice of one stream. (/dev/shm holds plain files.) */
    if (!strncmp(name, "/dev/", 5) && strncmp(name, "/dev/shm/", 9)) return 0;
    if (stat(name, &st) == 0) {
        if (!S_ISREG(st.st_mode)) return 0;
        id->dev = st.st_dev, id->ino = st.st_ino;
        return 1;
    }
    const char *slash = strrchr(name, '/');
    char *dir = slash ? strndup(name, slash == name ? 1 : (size_t)(slash - name)) : strdup(".");
    char *real = dir ? realpath(dir, NULL) : NULL;
    size_t len = (real ? strlen(real) : strlen(name)) + strlen(name) + 2;
    id->path = malloc(len);
    if (id->path && real)
        snprintf(id->path, len, "%s/%s", real, slash ? slash + 1 : name);
    else if (id->path) /* (its directory is missing: the name as given) */
        snprintf(id->path, len, "%s", name);
    free(dir), free(real);
    return id->path != NULL;
}

static int file_same(const file_id *a, const file_id *b)
{
    if (a->path || b->path) return a->path && b->path && !strcmp(a->path, b->path);
    return a->dev == b->dev && a->ino == b->ino;
}

/* Does an output name an input, or the same file as another output? 0, or -1 with
   the message in err (-2: out of memory). Either destroyed data without a word: the
   image replaced by the stats, the scene by the CSV. */
static int check_distinct(const char *const *inputs, const char *const *opts,
                          const char *const *paths, int n, char *err, size_t errlen)
{
    int ni = 0, bad = 0;
    while (inputs && inputs[ni]) ni++;
    file_id *in = calloc((size_t)ni + 1, sizeof *in), *out = calloc((size_t)n + 1, sizeof *out);
    int *in_ok = calloc((size_t)ni + 1, sizeof *in_ok);
    int *out_ok = calloc((size_t)n + 1, sizeof *out_ok);
    if (!in || !out || !in_ok || !out_ok) {
        snprintf(err, errlen, "out of memory");
        bad = -2;
    }
    for (int k = 0; !bad && k < ni; k++) in_ok[k] = file_identify(inputs[k], &in[k]);
    for (int k = 0; !bad && k < n; k++) {
        if (!paths[k] || !(out_ok[k] = file_identify(paths[k], &out[k]))) continue;
        for (int j = 0; !bad && j < ni; j++)
            if (in_ok[j] && file_same(&out[k], &in[j])) {
                snprintf(err, errlen, "%s %s: is the input file %s: it would be overwritten",
                         opts[k], paths[k], inputs[j]);
                bad = -1;
            }
        for (int j = 0; !bad && j < k; j++)
            if (out_ok[j] && file_same(&out[k], &out[j])) {
                snprintf(err, errlen, "%s %s: the same file as %s %s: one would overwrite the "
                         "other", opts[k], paths[k], opts[j], paths[j]);
                bad = -1;
            }
    }
    for (int k = 0; in && k < ni; k++) free(in[k].path);
    for (int k = 0; out && k < n; k++) free(out[k].path);
    free(in), free(out), free(in_ok), free(out_ok);
    return bad;
}

int vw_cli_check_files(const char *cmd, const char *const *inputs, const char *const *opts,
                       const char *const *paths, int n)
{
    char err[1024] = "";
    vw_status st = VW_OK;
    int distinct = vw_cli_is_output() ? check_distinct(inputs, opts, paths, n, err, sizeof err) : 0;
    if (distinct) st = distinct == -2 ? VW_E_NOMEM : VW_E_INPUT;
    for (int k = 0; k < n && st == VW_OK && vw_cli_is_output(); k++)
        if (paths[k] && check_writable(opts[k], paths[k], err, sizeof err)) st = VW_E_IO;
    st = vw_engine_agree(st, err, sizeof err);
    if (st == VW_OK) return VW_EXIT_OK;
    if (vw_cli_is_output()) vw_cli_error(cmd, "%s", err);
    return st == VW_E_INPUT ? VW_EXIT_USAGE : VW_EXIT_FAIL;
}

int vw_cli_check_scene_files(const char *cmd, const vw_scene *scene, const char *const *opts,
                             const char *const *paths, int n)
{
    /* Each file once, however many materials it defines (a PLY gives one a face): at
       most nstrings of them. Out of memory, the libraries go unchecked (the scene file
       itself was checked before it was read). */
    const char **in = NULL;
    if (vw_cli_is_output()) {
        char *seen = calloc(scene->nstrings + 1, 1);
        in = calloc(scene->nstrings + 1, sizeof *in);
        size_t k = 0;
        for (size_t m = 0; seen && in && m < scene->nmaterials; m++) {
            int f = scene->materials[m].file;
            if (f > 0 && (size_t)f <= scene->nstrings && !seen[f] && vw_scene_string(scene, f)) {
                seen[f] = 1;
                in[k++] = vw_scene_string(scene, f);
            }
        }
        if (!seen) free(in), in = NULL;
        free(seen);
    }
    int rc = vw_cli_check_files(cmd, in, opts, paths, n);
    free(in);
    return rc;
}

/* Is frame n of pattern the file out? */
static int frame_is(const char *pattern, long n, const file_id *out)
{
    char name[4096];
    file_id id;
    /* The pattern has exactly one integer conversion (vw_cli_frame_pattern). */
    int w = snprintf(name, sizeof name, pattern, (int)n);
    if (w < 0 || (size_t)w >= sizeof name || !file_identify(name, &id)) return 0;
    int same = file_same(out, &id);
    free(id.path);
    return same;
}

int vw_cli_frame_file(const char *pattern, const char *path, long nframes, int *frame)
{
    file_id out;
    if (!pattern || !path || !file_identify(path, &out)) return 0;
    /* The frame number is written into the name in decimal, zero-padded or not, and the
       pattern's own text may have digits around it ("f1%d.png"): every run of digits of
       the name, and 0 (which "%.0d" writes as nothing), is a candidate. */
    size_t len = strlen(path);
    int found = 0;
    for (size_t i = 0; !found && i <= len; i++) {
        for (size_t j = i; !found && j <= len && j - i <= 10; j++) {
            if (j > i && (path[j - 1] < '0' || path[j - 1] > '9')) break;
            if (j == i && i > 0) continue; /* the candidate 0 once */
            long n = 0;
            for (size_t k = i; k < j; k++) n = 10 * n + (path[k] - '0');
            if (n > INT_MAX) break;
            if ((found = frame_is(pattern, n, &out)) && frame) *frame = (int)n;
        }
    }
    /* And the frames a run will write, whatever the name says (a link named otherwise). */
    for (long f = 0; !found && f < nframes && f <= INT_MAX; f++)
        if ((found = frame_is(pattern, f, &out)) && frame) *frame = (int)f;
    free(out.path);
    return found;
}

int vw_cli_check_frames(const char *cmd, const char *pattern, const char *const *opts,
                        const char *const *paths, int n, long nframes)
{
    char err[1024] = "";
    vw_status st = VW_OK;
    for (int k = 0; pattern && k < n && st == VW_OK && vw_cli_is_output(); k++) {
        int frame;
        if (paths[k] && vw_cli_frame_file(pattern, paths[k], nframes, &frame)) {
            snprintf(err, sizeof err, "%s %s: frame %d of -o %s: one would overwrite the other",
                     opts[k], paths[k], frame, pattern);
            st = VW_E_INPUT;
        }
    }
    st = vw_engine_agree(st, err, sizeof err);
    if (st == VW_OK) return VW_EXIT_OK;
    if (vw_cli_is_output()) vw_cli_error(cmd, "%s", err);
    return VW_EXIT_USAGE;
}

int vw_cli_check_outputs(const char *cmd, const char *const *opts, const char *const *paths, int n)
{
    return vw_cli_check_files(cmd, NULL, opts, paths, n);
}

/* Rank 0's n values (collective; a copy to free). */
static double *first_values(const double *v, size_t n)
{
    double *first = malloc(n * sizeof *first + 1);
    if (!first) vw_engine_abort(VW_EXIT_FAIL, "vwalls: out of memory comparing the processes' input");
    memcpy(first, v, n * sizeof *first);
    vw_engine_broadcast(first, n * sizeof *first);
    return first;
}

int vw_cli_same_as_first(const char *cmd, const double *v, size_t n, const char *what)
{
    if (vw_engine_size() == 1) return 0;
    double *first = first_values(v, n);
    /* Bit for bit: the same text parsed by the same binary gives the same doubles. */
    vw_status mine = memcmp(first, v, n * sizeof *first) ? VW_E_INVAL : VW_OK;
    free(first);
    char msg[256];
    snprintf(msg, sizeof msg, "was given another %s than rank 0: every process must run the "
             "same command on the same input", what);
    if (vw_engine_agree(mine, msg, sizeof msg) == VW_OK) return 0;
    vw_cli_error(cmd, "%s", msg);
    return -1;
}

void vw_progress_begin(vw_progress *p, const char *label, int show)
{
    p->label = label;
    p->enabled = show != VW_PROGRESS_OFF && vw_cli_is_output() &&
                 (show == VW_PROGRESS_ON || isatty(2));
    p->start = p->last = vw_cli_now();
}

void vw_progress_update(vw_progress *p, double fraction, const char *note)
{
    if (!p->enabled) return;
    double now = vw_cli_now();
    if (now - p->last < 0.1 && fraction < 1.0) return;
    p->last = now;
    if (fraction < 0) fraction = 0;
    if (fraction > 1) fraction = 1;
    int filled = (int)(fraction * 30 + 0.5);
    char bar[31];
    for (int i = 0; i < 30; i++) bar[i] = i < filled ? '#' : '.';
    bar[30] = 0;
    double el = now - p->start;
    double eta = fraction > 0.01 ? el * (1 - fraction) / fraction : 0;
    fprintf(stderr, "\r%s [%s] %5.1f%% %5.1fs eta %4.0fs %s\033[K", p->label, bar, 100 * fraction,
            el, eta, note ? note : "");
    fflush(stderr);
}

void vw_progress_hide(const vw_progress *p)
{
    if (!p->enabled) return;
    fprintf(stderr, "\r\033[K");
    fflush(stderr);
}

void vw_progress_end(vw_progress *p) { vw_progress_hide(p); }

int vw_cli_appendf(char **buf, size_t *len, size_t *cap, const char *fmt, ...)
{
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int k = vsnprintf(*buf ? *buf + *len : NULL, *buf ? *cap - *len : 0, fmt, ap);
        va_end(ap);
        if (k < 0) return 0;
        if (*buf && *len + (size_t)k < *cap) {
            *len += (size_t)k;
            return 1;
        }
        size_t ncap = 2 * *cap + (size_t)k + 1;
        char *nb = realloc(*buf, ncap);
        if (!nb) {
            if (*buf) (*buf)[*len] = 0; /* (the try above may have written past it) */
            return 0;
        }
        if (!*buf) nb[0] = 0;
        *buf = nb;
        *cap = ncap;
    }
}

int vw_cli_same_options(const char *cmd, const char *const *names, const double *v, size_t n)
{
    if (vw_engine_size() == 1) return 0;
    double *first = first_values(v, n);
    /* The first option that differs, bit for bit (the same text parsed by the same
       binary gives the same doubles), with all its values: --cells is three. */
    size_t k = 0;
    while (k < n && !memcmp(&first[k], &v[k], sizeof *v)) k++;
    char msg[512] = "", mine[160] = "", theirs[160] = "";
    if (k < n) {
        size_t a = k, b = k;
        while (a > 0 && !strcmp(names[a - 1], names[k])) a--;
        while (b + 1 < n && !strcmp(names[b + 1], names[k])) b++;
        for (size_t i = a; i <= b; i++) {
            size_t lm = strlen(mine), lt = strlen(theirs);
            snprintf(mine + lm, sizeof mine - lm, "%s%g", i > a ? "x" : "", v[i]);
            snprintf(theirs + lt, sizeof theirs - lt, "%s%g", i > a ? "x" : "", first[i]);
        }
        snprintf(msg, sizeof msg, "was given another %s than rank 0 (%s, rank 0 %s): every "
                 "process must run the same command on the same input", names[k], mine, theirs);
    }
    free(first);
    if (vw_engine_agree(k < n ? VW_E_INVAL : VW_OK, msg, sizeof msg) == VW_OK) return 0;
    vw_cli_error(cmd, "%s", msg);
    return -1;
}

int vw_cli_same_scene(const char *cmd, const vw_scene *scene)
{
    if (vw_engine_size() == 1) return 0; /* the hash reads every byte of the scene */
    uint64_t h = vw_scene_fingerprint(scene);
    /* Two halves: a double holds 32 bits exactly. */
    const double v[2] = {(double)(uint32_t)(h >> 32), (double)(uint32_t)h};
    return vw_cli_same_as_first(cmd, v, 2, "scene");
}

int vw_cli_same_view(const char *cmd, int width, int height, long depth, const vw_camera *cam,
                     const vw_scene *scene)
{
    enum { MAXL = 64 };
    /* As many numbers on every process (the broadcast needs it), unused ones 0; the
       first MAXL lights and their count. */
    double v[6 + 10 + 1 + 6 * MAXL] = {0};
    size_t n = 0;
    v[n++] = width, v[n++] = height, v[n++] = (double)depth;
    v[n++] = cam->width, v[n++] = cam->height, v[n++] = cam->hither;
    for (int k = 0; k < 3; k++) v[n++] = cam->from[k], v[n++] = cam->at[k], v[n++] = cam->up[k];
    v[n++] = cam->angle;
    v[n++] = (double)scene->nlights;
    for (size_t l = 0; l < scene->nlights && l < MAXL; l++)
        for (int k = 0; k < 3; k++) v[n++] = scene->lights[l].pos[k], v[n++] = scene->lights[l].color[k];
    return vw_cli_same_as_first(cmd, v, sizeof v / sizeof v[0],
                                "view (image size, depth, camera or lights)");
}

const char *vw_cli_json_number(double x, char buf[32])
{
    if (isfinite(x)) snprintf(buf, 32, "%.17g", x);
    else snprintf(buf, 32, "null");
    return buf;
}

int vw_cli_json_string(char **buf, size_t *len, size_t *cap, const char *s)
{
    if (!s) return vw_cli_appendf(buf, len, cap, "null");
    int ok = vw_cli_appendf(buf, len, cap, "\"");
    for (; *s && ok; s++) {
        unsigned char ch = (unsigned char)*s;
        if (ch == '"' || ch == '\\') ok = vw_cli_appendf(buf, len, cap, "\\%c", ch);
        else if (ch < 0x20 || ch == 0x7f) ok = vw_cli_appendf(buf, len, cap, "\\u%04x", ch);
        else ok = vw_cli_appendf(buf, len, cap, "%c", ch);
    }
    return ok && vw_cli_appendf(buf, len, cap, "\"");
}

int vw_cli_stats_begin(char **buf, size_t *len, size_t *cap, const char *cmd, int workers)
{
    int p = vw_engine_size();
    int ok = vw_cli_appendf(buf, len, cap, "{\n  \"command\": ");
    ok = ok && vw_cli_json_string(buf, len, cap, cmd);
    return ok && vw_cli_appendf(buf, len, cap,
                                ",\n  \"version\": \"%s\",\n  \"engine\": {\"kind\": \"%s\", "
                                "\"processes\": %d, \"workers\": %d, \"workers_per_process\": %d}",
                                VW_VERSION_STRING, p > 1 ? "mpi" : "threads", p, workers * p,
                                workers);
}

int vw_cli_stats_end(const char *cmd, const char *path, char **buf, size_t *len, size_t *cap,
                     double t0, const char *const *phases, const double *secs, int nphases)
{
    char n[32], err[1024];
    int ok = vw_cli_appendf(buf, len, cap, ",\n  \"time_s\": {");
    for (int k = 0; k < nphases && ok; k++)
        ok = vw_cli_appendf(buf, len, cap, "\"%s\": %s, ", phases[k], vw_cli_json_number(secs[k], n));
    if (!ok || !vw_cli_appendf(buf, len, cap, "\"total\": %s}\n}\n",
                               vw_cli_json_number(vw_cli_now() - t0, n))) {
        vw_cli_error(cmd, "out of memory for the stats");
        return VW_EXIT_FAIL;
    }
    if (vw_cli_is_output() && vw_outfile_write(path, *buf, *len, err, sizeof err) != VW_OK) {
        vw_cli_error(cmd, "%s", err);
        return VW_EXIT_FAIL;
    }
    return VW_EXIT_OK;
}

int vw_cli_box_json(char **buf, size_t *len, size_t *cap, const double lo[3], const double hi[3])
{
    char n[6][32];
    return vw_cli_appendf(buf, len, cap, "[[%s, %s, %s], [%s, %s, %s]]",
                          vw_cli_json_number(lo[0], n[0]), vw_cli_json_number(lo[1], n[1]),
                          vw_cli_json_number(lo[2], n[2]), vw_cli_json_number(hi[0], n[3]),
                          vw_cli_json_number(hi[1], n[4]), vw_cli_json_number(hi[2], n[5]));
}

int vw_cli_scene_json(char **buf, size_t *len, size_t *cap, const vw_scene *s)
{
    double lo[3], hi[3];
    vw_scene_bounds(s, lo, hi);
    return vw_cli_appendf(buf, len, cap,
                          "\"objects\": %zu, \"spheres\": %zu, \"cones\": %zu, \"polygons\": %zu, "
                          "\"vertices\": %zu, \"materials\": %zu, \"lights\": %zu, \"bounds\": ",
                          vw_scene_count_objects(s), s->nspheres, s->ncones, s->npolygons,
                          s->nvertices, s->nmaterials, s->nlights) &&
           vw_cli_box_json(buf, len, cap, lo, hi);
}
