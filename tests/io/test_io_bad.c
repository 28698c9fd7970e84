/* test_io_bad.c - every file in tests/data/bad must be rejected with VW_E_INPUT, a
 * "name:LINE: " prefix and the message its first line promises ("# expect: ..."); and
 * with its line ends made CR alone or CRLF, with the same message (the same line).
 * A PLY file, whose first line must be "ply", says what it expects in a header line
 * "comment expect: ...".
 * Usage: test_io_bad DATA_DIR
 */
#define _GNU_SOURCE
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io_test_util.h"
#include "vw_test.h"
#include "vwalls/scene.h"

static int has_ext(const char *name, const char *ext)
{
    size_t n = strlen(name), m = strlen(ext);
    return n > m && !strcmp(name + n - m, ext);
}

/* Does err begin with "NAME:DIGITS: " where NAME is the file itself or, for errors
   inside a material library, an .mtl file? */
static int good_prefix(const char *err, const char *path)
{
    const char *p;
    size_t n = strlen(path);
    if (!strncmp(err, path, n) && err[n] == ':') {
        p = err + n + 1;
    } else {
        p = strstr(err, ".mtl:");
        if (!p)
            return 0;
        p += 5;
    }
    if (*p < '0' || *p > '9')
        return 0;
    while (*p >= '0' && *p <= '9')
        p++;
    return p[0] == ':' && p[1] == ' ';
}

/* The file read as text with other line ends (a library an OBJ names keeps its own)
   fails with the message err, word for word: a lone CR ends a line, CRLF is one line
   end. A CR-only OBJ used to read as one statement, and every NFF error named line 1. */
static void same_with_line_ends(const char *path, const char *dir, const char *err)
{
    size_t n;
    char *text = slurp(path, &n);
    CHECK(text != NULL && !memchr(text, '\r', n));
    for (int crlf = 0; crlf < 2; crlf++) {
        size_t m;
        char *t = vw_test_line_ends(text, n, crlf, &m), err2[1024] = "";
        vw_scene *s = (vw_scene *)1;
        vw_status st = has_ext(path, ".obj")   ? vw_scene_read_obj(path, t, m, dir, &s, err2, sizeof err2)
                       : has_ext(path, ".ply") ? vw_scene_read_ply(path, t, m, &s, err2, sizeof err2)
                                               : vw_scene_read_nff(path, t, m, &s, err2, sizeof err2);
        EXPECT(st == VW_E_INPUT && s == NULL && !strcmp(err, err2),
               "%s with %s line ends: status %d\n  message:  '%s'\n  with LF:  '%s'", path,
               crlf ? "CRLF" : "CR", (int)st, err2, err);
        free(t);
    }
    free(text);
}

int main(int argc, char **argv)
{
    CHECK(argc == 2);
    char dirpath[4096];
    snprintf(dirpath, sizeof dirpath, "%s/bad", argv[1]);
    DIR *d = opendir(dirpath);
    CHECK(d != NULL);
    int files = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        int ply = has_ext(e->d_name, ".ply");
        if (!has_ext(e->d_name, ".nff") && !has_ext(e->d_name, ".obj") && !ply)
            continue;
        char path[8192], line[512], err[1024] = "";
        snprintf(path, sizeof path, "%s/%s", dirpath, e->d_name);
        FILE *f = fopen(path, "r");
        CHECK(f != NULL);
        /* The first line; a PLY's must be "ply", so it says it in a header comment. */
        const char *tag = ply ? "comment expect: " : "# expect: ";
        int found = 0;
        while (!found && fgets(line, sizeof line, f)) {
            line[strcspn(line, "\r\n")] = '\0';
            found = !strncmp(line, tag, strlen(tag));
            if (!ply) break;
        }
        fclose(f);
        if (!found) {
            fprintf(stderr, "%s: %s lacks '%s'\n", path, ply ? "header" : "first line", tag);
            return 1;
        }
        const char *expect = line + strlen(tag);
        vw_scene *s = (vw_scene *)1;
        vw_status st = vw_scene_read_file(path, &s, err, sizeof err);
        printf("%-28s -> %s\n", e->d_name, err);
        if (st != VW_E_INPUT || s != NULL || !strstr(err, expect) || !good_prefix(err, path)) {
            fprintf(stderr, "%s: status %d (want %d), scene %p\n  message:  '%s'\n"
                            "  expected: 'NAME:LINE: ...%s...'\n",
                    path, (int)st, (int)VW_E_INPUT, (void *)s, err, expect);
            return 1;
        }
        same_with_line_ends(path, dirpath, err);
        files++;
    }
    closedir(d);
    printf("%d bad files rejected as promised\n", files);
    CHECK(files >= 15);

    /* A file that does not exist: "path: cannot open: reason". */
    char err[512];
    vw_scene *s;
    CHECK(vw_scene_read_file("/nonexistent/x.nff", &s, err, sizeof err) == VW_E_INPUT);
    CHECK(strstr(err, "/nonexistent/x.nff: cannot open: ") == err);
    CHECK(vw_scene_read_file("scene.txt", &s, err, sizeof err) == VW_E_INPUT);
    CHECK(strstr(err, "unknown scene format") != NULL);
    TEST_DONE();
}
