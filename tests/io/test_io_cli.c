/* test_io_cli.c - the gen and info subcommands, run in-process: exit statuses, one-line
 * errors naming the bad option, NFF on stdout and atomically into -o, and info on the
 * result and on a bad file (the parser's "file:line: message").
 * Usage: test_io_cli DATA_DIR
 */
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "commands.h"
#include "io_test_util.h"
#include "vw_test.h"

static char out_path[256], err_path[256];

/* Runs fn(argv) with stdout and stderr sent to files; returns its exit status. */
static int run(int (*fn)(int, char **), const char *const *args)
{
    char *argv[32];
    int argc = 0;
    while (args[argc]) {
        argv[argc] = (char *)args[argc];
        argc++;
    }
    argv[argc] = NULL;
    fflush(stdout);
    fflush(stderr);
    int o = dup(1), e = dup(2);
    int fo = open(out_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int fe = open(err_path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fo, 1);
    dup2(fe, 2);
    int rc = fn(argc, argv);
    fflush(stdout);
    fflush(stderr);
    dup2(o, 1);
    dup2(e, 2);
    close(o);
    close(e);
    close(fo);
    close(fe);
    return rc;
}

static char *text_of(const char *p)
{
    size_t n;
    char *t = slurp(p, &n);
    CHECK(t != NULL);
    return t;
}

static int lines(const char *t)
{
    int n = 0;
    for (; *t; t++)
        n += *t == '\n';
    return n;
}

int main(int argc, char **argv)
{
    CHECK(argc == 2);
    char dir[] = "/tmp/vw_io_cli_XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    snprintf(out_path, sizeof out_path, "%s/stdout", dir);
    snprintf(err_path, sizeof err_path, "%s/stderr", dir);
    char file[300];
    snprintf(file, sizeof file, "%s/flake.nff", dir);

    /* --help goes to stdout, exit 0. */
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "--help", NULL}), 0);
    char *t = text_of(out_path);
    CHECK(strstr(t, "usage: vwalls gen") != NULL);
    free(t);

    /* A bad option: one line naming it, exit 2. */
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "balls", "--bogus", NULL}), 2);
    t = text_of(err_path);
    printf("bad option: %s", t);
    CHECK(strncmp(t, "vwalls gen: ", 12) == 0 && strstr(t, "--bogus") && lines(t) == 1);
    free(t);
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "balls", "--size", "x", NULL}), 2);
    t = text_of(err_path);
    CHECK(strstr(t, "--size") && lines(t) == 1);
    free(t);
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "teapot", NULL}), 2);
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", NULL}), 2);
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "spheres", "--cluster", "2", NULL}), 2);
    /* An option the scene has no use for, or size 0, is an error, not a silent default. */
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "rings", "--size", "0", NULL}), 2);
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "cornell", "--size", "3", NULL}), 2);
    t = text_of(err_path);
    CHECK(strstr(t, "'cornell' takes no such option") && lines(t) == 1);
    free(t);
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "balls", "--count", "5", NULL}), 2);
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "tree", "--cluster", "0.5", NULL}), 2);
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "spheres", "--size", "2", NULL}), 2);
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "balls", "--seed", "3", NULL}), 2);
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "tree", "--size", "2", "--seed", "3", NULL}), 0);
    /* --seed: decimal digits only. strtoull took " -1" (a blank, then a sign) as
       2^64-1 and "0x10" as 16; the whole 64-bit range is accepted. */
    const char *bad_seeds[] = {" -1", "-1", "+1", " 1", "1 ", "0x10", "", "18446744073709551616"};
    for (size_t k = 0; k < sizeof bad_seeds / sizeof bad_seeds[0]; k++) {
        CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "spheres", "--count", "5", "--seed",
                                                      bad_seeds[k], NULL}), 2);
        t = text_of(err_path);
        CHECK(strstr(t, "--seed: bad value") && lines(t) == 1);
        free(t);
    }
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "spheres", "--count", "5", "--seed",
                                                  "18446744073709551615", NULL}), 0);
    /* An empty -o is a usage error, not a failed rename. */
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "cornell", "-o", "", NULL}), 2);
    t = text_of(err_path);
    CHECK(strcmp(t, "vwalls gen: -o: empty file name\n") == 0);
    free(t);

    /* -o must end in .nff, as the readers choose the format by the name: written as
       room.obj it would be read back as OBJ. A usage error, and nothing written. */
    snprintf(file, sizeof file, "%s/room.obj", dir);
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "room", "-o", file, NULL}), 2);
    CHECK(access(file, F_OK) != 0);
    t = text_of(err_path);
    CHECK(strstr(t, "vwalls gen: -o ") && strstr(t, "room.obj: written as NFF, which vwalls "
                    "reads only from a name ending in .nff") && lines(t) == 1);
    free(t);
    snprintf(file, sizeof file, "%s/ROOM.NFF", dir);
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "room", "-o", file, NULL}), 0);
    unlink(file);
    snprintf(file, sizeof file, "%s/flake.nff", dir);

    /* NFF to stdout equals NFF to -o. */
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "balls", "--size", "2", "--resolution",
                                                  "320x240", NULL}), 0);
    char *a = text_of(out_path);
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "balls", "--size", "2", "--resolution",
                                                  "320x240", "-o", file, NULL}), 0);
    char *b = text_of(file);
    CHECK(strcmp(a, b) == 0);
    CHECK(strstr(a, "resolution 320 240") != NULL);
    free(a);
    free(b);

    /* info on it. */
    CHECK_EQ_INT(run(vw_cmd_info, (const char *[]){"info", file, NULL}), 0);
    t = text_of(out_path);
    printf("%s", t);
    CHECK(strstr(t, "objects: 92 (spheres 91, cones 0, polygons 1)") != NULL);
    CHECK(strstr(t, "resolution 320x240") != NULL);
    free(t);
    CHECK_EQ_INT(run(vw_cmd_info, (const char *[]){"info", file, "--objects", NULL}), 0);
    t = text_of(out_path);
    CHECK(lines(t) == 8 + 3 + 92);   /* header lines, 3 lights, one line per object */
    CHECK(strstr(t, "\n0 polygon 4 vertices bounds -12 -12 -0.5  12 12 -0.5 material 0") != NULL);
    CHECK(strstr(t, "\n91 sphere bounds ") != NULL);
    free(t);

    /* info on a bad file: the parser's message, exit 2. */
    char bad[4096];
    snprintf(bad, sizeof bad, "%s/bad/unknown_keyword.nff", argv[1]);
    CHECK_EQ_INT(run(vw_cmd_info, (const char *[]){"info", bad, NULL}), 2);
    t = text_of(err_path);
    printf("bad file: %s", t);
    CHECK(strstr(t, "unknown_keyword.nff:9: unknown keyword 'q'") != NULL && lines(t) == 1);
    free(t);
    CHECK_EQ_INT(run(vw_cmd_info, (const char *[]){"info", "--frob", NULL}), 2);
    CHECK_EQ_INT(run(vw_cmd_info, (const char *[]){"info", NULL}), 2);
    /* info on an OBJ: no camera. */
    snprintf(bad, sizeof bad, "%s/good/cube.obj", argv[1]);
    CHECK_EQ_INT(run(vw_cmd_info, (const char *[]){"info", bad, NULL}), 0);
    t = text_of(out_path);
    CHECK(strstr(t, "camera: none") != NULL);
    free(t);
    /* info on an OBJ whose library is missing: read, with its warnings on stderr, one
       line each (it used to be refused, status 2, for the library). */
    snprintf(bad, sizeof bad, "%s/warn/obj_missing_mtl.obj", argv[1]);
    CHECK_EQ_INT(run(vw_cmd_info, (const char *[]){"info", bad, NULL}), 0);
    t = text_of(err_path);
    printf("missing library: %s", t);
    CHECK(lines(t) == 2 && strstr(t, "obj_missing_mtl.obj:5: warning: material library ") != NULL &&
          strstr(t, "obj_missing_mtl.obj:11: warning: material 'red' is not defined") != NULL);
    free(t);

    /* -o into a missing directory: exit 1, nothing written. */
    snprintf(file, sizeof file, "%s/missing/x.nff", dir);
    CHECK_EQ_INT(run(vw_cmd_gen, (const char *[]){"gen", "cornell", "-o", file, NULL}), 1);
    CHECK(access(file, F_OK) != 0);

    snprintf(file, sizeof file, "%s/flake.nff", dir);
    unlink(file);
    unlink(out_path);
    unlink(err_path);
    rmdir(dir);
    TEST_DONE();
}
