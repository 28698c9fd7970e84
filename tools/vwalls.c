/* vwalls.c - the vwalls command: dispatches to one subcommand per file (cmd_*.c).
 * The same binary runs alone (threads engine) and under mpirun (MPI engine).
 */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "cli.h"
#include "commands.h"

typedef struct vw_command {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} vw_command;

static const vw_command commands[] = {
    {"gen", vw_cmd_gen, "write a generated scene (balls, rings, tree, spheres, cornell, room) as NFF"},
    {"info", vw_cmd_info, "describe a scene: counts, bounds, camera, lights (--objects: every object)"},
    {"example-pairs", vw_cmd_example_pairs, "count touching sphere pairs (the example module)"},
    {"example-components", vw_cmd_example_components,
     "connected components of touching spheres (the second example module)"},
    {"render", vw_cmd_render, "ray trace an NFF, OBJ or PLY scene, distributed over cells"},
    {"radiosity", vw_cmd_radiosity, "progressive radiosity of an OBJ, NFF or PLY scene, distributed over cells"},
    {"animate", vw_cmd_animate, "run an edit script on a scene: collision-checked moves, a frame per 'frame'"},
    {"edit", vw_cmd_edit, "the edit language interactively from stdin"},
    {"bench", vw_cmd_bench, "how the ray tracer scales here: layouts x workers side by side, same image"},
};

static void usage(FILE *f)
{
    fprintf(f,
            "usage: vwalls COMMAND [options]\n"
            "       vwalls help COMMAND   the command's options (as vwalls COMMAND --help)\n"
            "       vwalls --help         this text\n"
            "       vwalls --version      the version\n"
            "\n"
            "Distributed geometric computation with the Virtual Walls method: space is cut\n"
            "into cells by axis-aligned walls; cells compute locally and talk to neighbours.\n"
            "Runs on worker threads; the same command runs under mpirun on several machines.\n"
            "\ncommands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        fprintf(f, "  %-19s %s\n", commands[i].name, commands[i].summary);
    fprintf(f, "\nexit status: 0 success, 2 bad input or usage, 1 any other failure\n");
}

/* SIGINT, SIGTERM, SIGHUP while an output is being written: its temporary file
   ("path.tmp.XXXXXX") is removed, then the signal's default action ends the process,
   so the exit status still says which signal killed it. Only async-signal-safe calls. */
static void on_fatal_signal(int sig)
{
    vw_outfile_remove_temps();
    signal(sig, SIG_DFL);
    raise(sig); /* blocked until the handler returns, then it ends the process */
}

/* A signal the process was started with ignored (nohup, a background job of a
   script) stays ignored. The three block each other while the handler runs. */
static void install_signal_handlers(void)
{
    static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
    enum { N = sizeof sigs / sizeof sigs[0] };
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_fatal_signal;
    sigemptyset(&sa.sa_mask);
    for (int k = 0; k < N; k++) sigaddset(&sa.sa_mask, sigs[k]);
    for (int k = 0; k < N; k++) {
        struct sigaction old;
        if (sigaction(sigs[k], NULL, &old) == 0 && old.sa_handler != SIG_IGN)
            sigaction(sigs[k], &sa, NULL);
    }
}

static const vw_command *find_command(const char *name)
{
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (!strcmp(name, commands[i].name)) return &commands[i];
    if (vw_cli_is_output()) fprintf(stderr, "vwalls: unknown command '%s' (try vwalls --help)\n", name);
    return NULL;
}

/* Under MPI every process runs main, but only the output process (rank 0) prints: the
   others' standard output goes to /dev/null, so help, version, info and a scene written
   by gen to stdout appear once. Their standard error stays open (a rank that must tell
   why it stopped the job still can); main's own messages are printed by rank 0 only. */
static int run(int argc, char **argv)
{
    int out = vw_cli_is_output();
    if (!out && !freopen("/dev/null", "w", stdout)) return VW_EXIT_FAIL;
    if (argc < 2) {
        if (out) usage(stderr);
        return VW_EXIT_USAGE;
    }
    if (!strcmp(argv[1], "--help") || !strcmp(argv[1], "-h") ||
        (!strcmp(argv[1], "help") && argc == 2)) {
        usage(stdout);
        return VW_EXIT_OK;
    }
    if (!strcmp(argv[1], "--version")) {
        printf("vwalls %s\n", vw_version());
        return VW_EXIT_OK;
    }
    if (!strcmp(argv[1], "help")) { /* vwalls help CMD: vwalls CMD --help */
        const vw_command *c = argc == 3 ? find_command(argv[2]) : NULL;
        if (!c) {
            if (argc != 3 && out) fprintf(stderr, "vwalls help: one command name (try vwalls --help)\n");
            return VW_EXIT_USAGE;
        }
        char *help_argv[] = {argv[2], "--help", NULL};
        return c->run(2, help_argv);
    }
    const vw_command *c = find_command(argv[1]);
    if (!c) return VW_EXIT_USAGE;
    install_signal_handlers();
    return c->run(argc - 1, argv + 1);
}

/* A command's answers on standard output that never arrived (a full disk, a closed
   pipe's reader gone) fail the command: edit's and animate's answers, render's summary,
   gen's scene, info's description. Checked once here for every command, after the
   last printf, as the C library only reports it when the buffer is written. */
static int stdout_status(const char *cmd, int rc)
{
    errno = 0;
    int failed = fflush(stdout) != 0;
    int err = errno;
    failed |= ferror(stdout) != 0;
    if (!failed) return rc;
    fprintf(stderr, "vwalls%s%s: cannot write to standard output%s%s\n", cmd ? " " : "",
            cmd ? cmd : "", err ? ": " : "", err ? strerror(err) : "");
    return rc == VW_EXIT_OK ? VW_EXIT_FAIL : rc;
}

int main(int argc, char **argv)
{
    vw_cli_engine_init(&argc, &argv);
    /* Every command ends here on every process, past its last collective call: the
       place where all take the job's status (only the output process writes files). */
    const char *cmd = argc > 1 && argv[1][0] != '-' ? argv[1] : NULL; /* not --help */
    int rc = vw_cli_job_status(cmd, stdout_status(cmd, run(argc, argv)));
    vw_cli_engine_finish();
    return rc;
}
