/* tools/cli.h - what every vwalls subcommand shares: option values, engine set-up,
 * messages and the progress bar. (Output files are written by vw_outfile.)
 */
#ifndef VW_TOOLS_CLI_H
#define VW_TOOLS_CLI_H

#include <stddef.h>
#include <stdint.h>
#include "vwalls/vwalls.h"

/* Exit statuses of every subcommand. */
enum { VW_EXIT_OK = 0, VW_EXIT_FAIL = 1, VW_EXIT_USAGE = 2 };

/* Print "vwalls CMD: message" on stderr (only on the output process under MPI). */
void vw_cli_error(const char *cmd, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Option values: each returns 0 and stores the value, or prints
   "vwalls CMD: --opt: bad value 'x' (expected ...)" and returns -1. A real number is
   read as strtod reads it but in decimal only (with or without an exponent: "1e-3",
   "2.5E2"): no hexadecimal float ("0x10", "-0X1p3"), which strtod also takes, and,
   as in whole numbers, no white space or '+' before it. */
int vw_cli_int(const char *cmd, const char *opt, const char *s, long lo, long hi, long *out);
int vw_cli_double(const char *cmd, const char *opt, const char *s, double lo, double hi,
                  double *out);
int vw_cli_size(const char *cmd, const char *opt, const char *s, int *w, int *h);  /* WxH */
/* strtod for the options' real numbers (vw_strtod_decimal: decimal notation, no white
   space or '+' first; otherwise no conversion, *end = s), errno 0 for one too small to
   hold (rounded to a denormal or zero, a fine value), ERANGE for an overflow. */
double vw_cli_strtod(const char *s, char **end);
/* A field of view in degrees: above 0 and below 180, the range of an NFF 'angle'
   (src/io/nff.c), so an option takes every angle a scene file may give and no other. */
int vw_cli_fov_ok(double deg);
int vw_cli_angle(const char *cmd, const char *opt, const char *s, double *out);
/* Between min and max comma-separated numbers (shape names them in the message, like
   "X,Y,Z"), each finite and at most FLT_MAX in size, the scene files' range; *n (when
   not NULL) gets their count. */
int vw_cli_numbers(const char *cmd, const char *opt, const char *s, const char *shape,
                   double *out, int min, int max, int *n);
/* A box given as X0,Y0,Z0,X1,Y1,Z1 (--world), its low corner below its high corner on
   every axis. */
int vw_cli_box(const char *cmd, const char *opt, const char *s, vw_box *out);
int vw_cli_layout(const char *cmd, const char *opt, const char *s, int dims[3]);
/* A frame file pattern (-o of animate and edit): a .png name with exactly one integer
   conversion for the frame number (%d or %i, with flags 0-+ #, a width and a precision
   of at most two digits each) and %% for a percent sign; anything else (no
   conversion, two, %s, %n, ...) is an error, since the pattern becomes a printf
   format. */
int vw_cli_frame_pattern(const char *cmd, const char *opt, const char *s);

/* The value after option argv[*i] (advancing *i), or an error and NULL: when there is
   none, or it is an option itself ("--stats --quiet"). */
const char *vw_cli_value(const char *cmd, int argc, char **argv, int *i);
/* The ray tracer's image options, alike in every command that renders: --size WxH and
   --depth D (1 to 64). 1 when argv[*i] is one of them (its value taken, *i advanced), 0
   when it is not, -1 after "vwalls CMD: ...: bad value" for a bad one. */
int vw_cli_image_option(const char *cmd, int argc, char **argv, int *i, int *width, int *height,
                        long *depth);
/* An argument that no option of the command took: the scene when it is the first such
   one (*scene NULL), else "vwalls CMD: more than one scene: ..." or, for what looks
   like an option ("-x", not "-"), "unknown option '-x' (try --help)", and -1. */
int vw_cli_scene_arg(const char *cmd, const char *a, const char **scene);
/* The same for an option naming an output file: an empty name is an error too
   ("vwalls CMD: -o: empty file name"), caught with the other usage errors instead of
   when the file is written. */
const char *vw_cli_output(const char *cmd, int argc, char **argv, int *i);

/* An output whose kind its name's ending chooses (-o x.png) must have a name before
   the ending: 0, or for ".png" or "dir/.png" "vwalls CMD: OPT PATH: no file name before
   the ending '.png' ..." and -1. */
int vw_cli_named(const char *cmd, const char *opt, const char *path);

/* An output that vwalls reads back as a scene (gen -o: NFF, radiosity -o: PLY), which
   it recognises by the name's ending: 0 when path ends in ext (".nff", any case) or is
   a device or a FIFO (not read back by name), else "vwalls CMD: OPT PATH: written as
   FORMAT, which vwalls reads only from a name ending in EXT" and -1 (and -1 from
   vw_cli_named for a name that is nothing but the ending). */
int vw_cli_scene_output(const char *cmd, const char *opt, const char *path, const char *ext,
                        const char *format);

/* The image size the ray tracer would take from the scene file's camera (path, as
   read into cam) when no --size was given (width 0): 0 when it is at most 16384 on a
   side, else -1 and "FILE:LINE: resolution WxH too large for the ray tracer (...): give
   --size WxH ..." (the line of the file's 'resolution', as the reader recorded it). */
int vw_cli_scene_size(const char *path, const vw_camera *cam, int width);

/* Fault injection for tests: is name one of the comma-separated words of the
   environment variable VW_FAULT (e.g. VW_FAULT=ledger: vwalls radiosity takes its
   energy ledger as off)? vw_test_fault, which the applications use too. Never set
   outside tests. */
int vw_cli_fault(const char *name);

/* Can the output files be made: for each of the n paths given (NULL: none), its
   directory exists and may be written into, and it is not a directory? Checked on the
   output process (the one that writes) before the work, so that a result is not
   computed and then lost, or half of the outputs written; the writes at the end still
   report their own errors (a full disk, a directory removed meanwhile). VW_EXIT_OK, or
   VW_EXIT_FAIL on every process with "vwalls CMD: OPT PATH: cannot write: DIR: why"
   printed once; VW_EXIT_USAGE when two of them are one file (vw_cli_check_files).
   Collective under MPI. */
int vw_cli_check_outputs(const char *cmd, const char *const *opts, const char *const *paths, int n);
/* vw_cli_check_outputs, which calls it with no inputs, and first: no output is one of
   the inputs (the files the command reads, a NULL-terminated list; NULL: none) and no
   two outputs are the same file (compared by device and inode when the file exists, by
   the resolved name when it does not; devices and FIFOs, /dev/null or /dev/stdout, are
   exempt). Such a pair is VW_EXIT_USAGE, with "vwalls CMD: OPT PATH: is the input file
   IN: it would be overwritten" or "OPT PATH: the same file as OPT2 PATH2: one would
   overwrite the other"; nothing has been written. Collective under MPI. */
int vw_cli_check_files(const char *cmd, const char *const *inputs, const char *const *opts,
                       const char *const *paths, int n);

/* vw_cli_check_files after the scene is read, with the files it was read from as the
   inputs: its material libraries (an OBJ's mtllib, named by its materials), which
   "render x.obj --stats x.mtl" replaced. Collective under MPI (every process calls it
   with its own copy of the scene; the output process checks). */
int vw_cli_check_scene_files(const char *cmd, const vw_scene *scene, const char *const *opts,
                             const char *const *paths, int n);
/* Is path one of the frame files of pattern (animate's and edit's -o, valid by
   vw_cli_frame_pattern): the same file as the pattern's name for a frame number its
   name holds, or for one of the frames 0 to nframes-1 (those a run will write; 0 when
   not known)? 1 and the number in *frame, else 0. Devices are nobody's frames (0). */
int vw_cli_frame_file(const char *pattern, const char *path, long nframes, int *frame);
/* The outputs other than the frames (--log, --stats) against the frame files of
   pattern (NULL: none), as vw_cli_frame_file sees them: the frame number each path's
   name holds, and every frame 0 to nframes-1 (those the run will write, so a link to
   frame 3 named otherwise is seen; 0 when not known): VW_EXIT_OK, or VW_EXIT_USAGE on
   every process with "vwalls CMD: OPT PATH: frame N of -o PATTERN: one would overwrite
   the other" printed once. Collective under MPI. */
int vw_cli_check_frames(const char *cmd, const char *pattern, const char *const *opts,
                        const char *const *paths, int n, long nframes);

/* Is this process the one that prints (rank 0, or no MPI)? Valid after vw_cli_engine_init. */
int vw_cli_is_output(void);
/* Workers of the whole job: --workers W (0: the world's default, one per core, and under
   MPI the fewest cores of any host, as the world takes them) times the processes, the
   same on every process. Collective under MPI; valid after vw_cli_engine_init. */
int vw_cli_job_workers(long workers);

/* Under MPI, checks that every process holds the same n numbers v as the first process
   (collective: every process calls it with the same n). 0 when they do, or without MPI;
   else -1 on every process, and the output process prints "vwalls CMD: rank R was given
   another WHAT than rank 0" (a scene file that differs between hosts, another option). */
int vw_cli_same_as_first(const char *cmd, const double *v, size_t n, const char *what);

/* vw_cli_same_as_first for options: names[k] is the option that gave v[k] (an option of
   several numbers, like --cells, repeats its name over consecutive entries). The
   message names the first option that differs and both values: "rank R: was given
   another --sf than rank 0 (0.0001, rank 0 0.001): ...". */
int vw_cli_same_options(const char *cmd, const char *const *names, const double *v, size_t n);

/* vw_cli_same_as_first for what the ray tracer draws: the image size and depth asked
   for, the camera and the scene's lights (the world's own check at commit compares only
   the cells and the objects' bounds). */
int vw_cli_same_view(const char *cmd, int width, int height, long depth, const vw_camera *cam,
                     const vw_scene *scene);
/* vw_cli_same_as_first for the scene itself (vw_scene_fingerprint: its objects, vertices,
   materials, lights and background; not its camera): a file that differs on one host
   in anything the world's bounds do not show (a material, a normal, an inner vertex)
   drew or solved wrongly without a word. */
int vw_cli_same_scene(const char *cmd, const vw_scene *scene);

/* MPI set-up for the command line: initialises MPI when the process was started by a
   launcher (and the build has MPI), so the same binary runs with and without mpirun.
   vw_cli_engine_finish finalises what init started. Both are safe to call without MPI. */
void vw_cli_engine_init(int *argc, char ***argv);
void vw_cli_engine_finish(void);
/* The exit status of the whole job, from this process's (collective: every process calls
   it once, when its command has returned, before vw_cli_engine_finish). Under MPI only
   the output process writes the outputs and checks results, so it alone may know that
   the run failed (a --stats file it cannot create); every process now exits with the
   status of the lowest failing rank, so whatever reads any rank's status (a launcher, a
   batch system, a script each rank runs) sees the failure. The commands report their
   own failures (from the output process); when it succeeded and another process did
   not, it says which: "vwalls CMD: rank R: failed with exit status S". Without MPI, rc
   as it is. */
int vw_cli_job_status(const char *cmd, int rc);

/* The agreement that ends one phase of a command (collective: every process calls it at
   the same point, before the phase's next collective call). A check whose answer can
   differ between processes (a file on its host, its memory, a check only the output
   process makes) must end in one: a process that returned at once would wait in the
   job's final agreement while the others wait for it in the next collective call.
   rc is this process's exit status so far (VW_EXIT_OK, or how it failed) and msg (of
   size len) its line when it failed, as the single process prints it: "vwalls CMD:
   what" (vw_cli_fail) or a file's own "file:line: what". Returns the status of the
   lowest failing rank, on every process (VW_EXIT_OK when none failed); the output
   process has then printed that rank's line, naming it under MPI as vw_engine_agree
   does: "vwalls CMD: rank R: what", "rank R: file:line: what". */
int vw_cli_agree(const char *cmd, int rc, char *msg, size_t len);
/* Writes "vwalls CMD: " and the printf output into msg (of size len), a line for
   vw_cli_agree, and returns rc: rc = vw_cli_fail(CMD, VW_EXIT_USAGE, msg, len, ...). */
int vw_cli_fail(const char *cmd, int rc, char *msg, size_t len, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

/* A progress bar on stderr (see vw_progress_begin): a fraction in [0,1] and
   a short note (e.g. "2.1 Mrays/s"); redrawn at most ten times a second. Safe to call
   from one thread at a time. */
typedef struct vw_progress {
    const char *label;
    int enabled;
    double start, last;
} vw_progress;
/* show: VW_PROGRESS_OFF (--quiet, or not the output process), VW_PROGRESS_AUTO (a bar when
   stderr is a terminal) or VW_PROGRESS_ON (--progress: also into a pipe, as under mpirun,
   whose launcher forwards the output process's stderr through one). */
enum { VW_PROGRESS_OFF = -1, VW_PROGRESS_AUTO = 0, VW_PROGRESS_ON = 1 };
void vw_progress_begin(vw_progress *p, const char *label, int show);
void vw_progress_update(vw_progress *p, double fraction, const char *note);
void vw_progress_end(vw_progress *p);
/* Wipes the bar for a line of text; the next update draws it again. */
void vw_progress_hide(const vw_progress *p);

double vw_cli_now(void);
/* How many processes of the job run on this host (the launcher's environment; 1 when
   it does not say). */
int vw_cli_local_processes(void);
/* n bytes for a message: "1.23 GB", "45 MB" or "678 kB" (in buf). */
const char *vw_cli_bytes(double n, char *buf, size_t len);
/* Workers against the cores they run on, for a message (in buf): "3 workers on 2 cores";
   under MPI a process's, against its share of its host's cores (vw_engine_core_share):
   "1 worker on 0.67 of a core in each process". */
const char *vw_cli_crowding(int workers, double cores, char *buf, size_t len);

/* Appends printf output to the string *buf (length *len, capacity *cap; *buf may start
   NULL with both 0), growing it as needed. Returns 0 when out of memory, and then leaves
   the string as it was. */
int vw_cli_appendf(char **buf, size_t *len, size_t *cap, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

/* The stats JSON of the commands that run no world (gen, info, bench; the others write
   theirs with vw_world_write_stats): DESIGN's section 9 asks every command for
   --stats FILE. vw_cli_stats_begin starts the object with the members every stats file
   opens with: "command", "version", "engine" (kind, processes, workers: the job's,
   workers_per_process); the caller appends its own members, each ",\n  \"name\": ...",
   and vw_cli_stats_end closes the object and writes it to path on the output process
   through vw_outfile (complete or absent). Its last member is "time_s": the nphases
   phases' seconds by name (plain names: they are not escaped), then "total", the time
   since t0. Each returns 0 when out of memory (append) or VW_EXIT_OK/VW_EXIT_FAIL
   (end, after "vwalls CMD: path: why"). */
int vw_cli_stats_begin(char **buf, size_t *len, size_t *cap, const char *cmd, int workers);
int vw_cli_stats_end(const char *cmd, const char *path, char **buf, size_t *len, size_t *cap,
                     double t0, const char *const *phases, const double *secs, int nphases);
/* A JSON string (quoted, escaped) appended, as vw_cli_appendf; NULL is null. */
int vw_cli_json_string(char **buf, size_t *len, size_t *cap, const char *s);
/* x as a JSON number ("%.17g"), or null: JSON has no NaN nor infinity, and "nan" makes
   the whole stats file unreadable. In buf. */
const char *vw_cli_json_number(double x, char buf[32]);
/* A scene's member of the stats JSON: "objects", "spheres", "cones", "polygons",
   "vertices", "materials", "lights" and "bounds" [[lo], [hi]], appended after
   ",\n  \"scene\": {" and what the caller puts first (its "file" or "generator") and
   ", ". */
int vw_cli_scene_json(char **buf, size_t *len, size_t *cap, const vw_scene *s);
/* A box as JSON, [[lo], [hi]], appended. 0 when out of memory. */
int vw_cli_box_json(char **buf, size_t *len, size_t *cap, const double lo[3], const double hi[3]);

#endif
