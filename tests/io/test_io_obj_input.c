/* test_io_obj_input.c - what the OBJ and MTL readers take as input: a line holding a
 * NUL byte or another control character is refused at its physical line (binary data
 * named as an OBJ used to read as an empty mesh), while tab, VT, FF, UTF-8 and Latin-1
 * bytes stay accepted; a UTF-8 byte order mark is skipped; a keyword the format does not
 * define is one warning per file (its first line, the keyword shown printable), and no
 * statement of the OBJ specification warns; a file with no faces is an empty scene, as
 * an NFF with only its 'v' block is.
 * Usage: test_io_obj_input (no data: every input is made here)
 */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io_test_util.h"
#include "vw_test.h"

static char warnings[8][1024];
static int nwarnings;

static void collect(const char *msg, void *user)
{
    (void)user;
    if (nwarnings < 8)
        snprintf(warnings[nwarnings], sizeof warnings[0], "%s", msg);
    nwarnings++;
}

static const char TRI[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

/* Reads n bytes of OBJ text (dir: where libraries are, or NULL); the warnings are
   collected afresh. */
static vw_status read_obj(const char *text, size_t n, const char *dir, vw_scene **s,
                          char *err, size_t errlen)
{
    nwarnings = 0;
    *s = (vw_scene *)1;
    return vw_scene_read_obj("t.obj", text, n, dir, s, err, errlen);
}

/* The text (n bytes) is refused with exactly the message want, also with CR or CRLF line
   ends (the same line named). */
static void refused(const char *text, size_t n, const char *want)
{
    for (int ends = -1; ends < 2; ends++) {
        size_t m = n;
        char *t = ends < 0 ? NULL : vw_test_line_ends(text, n, ends, &m), err[512] = "";
        vw_scene *s;
        vw_status st = read_obj(t ? t : text, m, NULL, &s, err, sizeof err);
        EXPECT(st == VW_E_INPUT && s == NULL && !strcmp(err, want),
               "line ends %d: status %d, message '%s', expected '%s'", ends, (int)st, err, want);
        free(t);
    }
}

/* The text is read, with nwant warnings and polys polygons. */
static void accepted(const char *text, size_t n, int nwant, size_t polys)
{
    char err[512] = "";
    vw_scene *s;
    vw_status st = read_obj(text, n, NULL, &s, err, sizeof err);
    EXPECT(st == VW_OK && s && s->npolygons == polys && nwarnings == nwant,
           "status %d (%s), %zu polygons (want %zu), %d warnings (want %d): '%s'", (int)st, err,
           st == VW_OK ? s->npolygons : 0, polys, nwarnings, nwant, nwarnings ? warnings[0] : "");
    if (st == VW_OK)
        vw_scene_free(s);
}

static void binary_bytes(void)
{
    /* A NUL byte anywhere on a line, a comment's too. */
    static const char nul_comment[] = "v 0 0 0\nv 1 0 0\n# made by \0 x\nv 0 1 0\nf 1 2 3\n";
    refused(nul_comment, sizeof nul_comment - 1, "t.obj:3: a NUL byte: binary data, not OBJ text");
    static const char nul_number[] = "v 0 0 0\nv 1 0\0 0\n";
    refused(nul_number, sizeof nul_number - 1, "t.obj:2: a NUL byte: binary data, not OBJ text");
    /* On a continued line, the physical line of the byte. */
    static const char continued[] = "v 0 0 0\nf 1 \\\n 2 \\\n\x01 3\n";
    refused(continued, sizeof continued - 1,
            "t.obj:4: control character 0x01: binary data, not OBJ text");
    /* Every control character but the blanks and line ends, and DEL. */
    for (int c = 1; c < 0x80; c++) {
        if (c >= 0x20 && c != 0x7f)
            continue;
        char text[64], want[128];
        int n = snprintf(text, sizeof text, "v 0 0 0\n# x%cy\n", c);
        if (c == '\t' || c == '\v' || c == '\f' || c == '\n' || c == '\r') {
            /* A line end starts a line "y": an unknown keyword. */
            accepted(text, (size_t)n, c == '\n' || c == '\r', 0);
            continue;
        }
        snprintf(want, sizeof want, "t.obj:2: control character 0x%02x: binary data, not OBJ text",
                 c);
        refused(text, (size_t)n, want);
    }
    /* Random bytes, as `vwalls render garbage.obj` got: refused, never an empty mesh. */
    char junk[512];
    uint64_t z = 7;
    for (int round = 0; round < 200; round++) {
        for (size_t i = 0; i < sizeof junk; i++)
            junk[i] = (char)(vw_test_mix(z++) & 0xff);
        char err[512];
        vw_scene *s;
        vw_status st = read_obj(junk, sizeof junk, NULL, &s, err, sizeof err);
        EXPECT(st == VW_E_INPUT && s == NULL && strstr(err, "binary data, not OBJ text"),
               "random bytes, round %d: status %d, '%s'", round, (int)st, err);
    }
}

static void text_bytes(void)
{
    /* Tab, VT and FF are blanks; UTF-8 and Latin-1 in comments and names are text. */
    static const char blanks[] = "v\t0 0\v0\nv 1\f0 0\nv 0 1 0\nf 1 2 3\n";
    accepted(blanks, sizeof blanks - 1, 0, 1);
    static const char utf8[] = "# Würfel – exportiert\ng Kühlschrank\no \xe5\x86\xb0\xe7\xae\xb1\n"
                               "usemtl Rot\xc3\xa9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    accepted(utf8, sizeof utf8 - 1, 0, 1);
    static const char latin1[] = "# W\xfcrfel\nusemtl Rot\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    accepted(latin1, sizeof latin1 - 1, 0, 1);
    /* A UTF-8 byte order mark (Notepad's) is not part of the first keyword: the vertex
       on the first line is read, with no warning. */
    static const char bom[] = "\xef\xbb\xbfv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    accepted(bom, sizeof bom - 1, 0, 1);
}

static void keywords(void)
{
    /* Every statement of the OBJ specification is read or ignored without a word. */
    static const char *const spec[] = {
        "v", "vt", "vn", "vp", "f", "l", "p", "g", "o", "s", "mg", "usemtl", "mtllib",
        "call", "csh", "cstype", "deg", "bmat", "step", "curv", "curv2", "surf", "parm",
        "trim", "hole", "scrv", "sp", "end", "con", "lod", "maplib", "usemap", "c_interp",
        "d_interp", "shadow_obj", "trace_obj", "bevel", "ctech", "stech"};
    char text[4096];
    size_t n = (size_t)snprintf(text, sizeof text, "%s", TRI);
    for (size_t i = 0; i < sizeof spec / sizeof spec[0]; i++) {
        /* Arguments the statements read take. */
        const char *args = !strcmp(spec[i], "v") || !strcmp(spec[i], "vn") ? " 0 0 1"
                           : !strcmp(spec[i], "vt") ? " 0.5"
                           : !strcmp(spec[i], "f") ? " 1 2 3"
                           : !strcmp(spec[i], "usemtl") ? " red" : " 1";
        n += (size_t)snprintf(text + n, sizeof text - n, "%s%s\n", spec[i], args);
    }
    accepted(text, n, 0, 2);

    /* Unknown keywords: one warning per file, at the first one, the rest read. */
    static const char unknown[] = "v 0 0 0\nv 1 0 0\nbogus 1 2\nv 0 1 0\nhello world\n"
                                  "f 1 2 3\nbogus again\n";
    accepted(unknown, sizeof unknown - 1, 1, 1);
    EXPECT(!strcmp(warnings[0], "t.obj:3: warning: unknown keyword 'bogus' (not an OBJ "
                                "statement): ignored, as are any others in this file"),
           "'%s'", warnings[0]);
    /* Shown printable and bounded: bytes from 0x80 up and the quote as '?'. */
    static const char shown[] = "# x\nV\xc3\xa9rtex'" "0123456789012345678901234567890123456789 1\n";
    accepted(shown, sizeof shown - 1, 1, 0);
    EXPECT(strstr(warnings[0], "t.obj:2: warning: unknown keyword 'V??rtex?01234567890123456789"
                               "012345678901...' (not an OBJ statement)") == warnings[0],
           "'%s'", warnings[0]);
    /* Text that is no OBJ at all: read as nothing, but not without a word. */
    static const char prose[] = "Dear user,\nthis is a letter.\n";
    accepted(prose, sizeof prose - 1, 1, 0);
    CHECK(strstr(warnings[0], "t.obj:1: warning: unknown keyword 'Dear'") == warnings[0]);
}

/* The same in a material library: binary data refused at the library's line, one warning
   per library for its unknown keywords, the rest of the specification and the usual
   extensions silent. */
static void libraries(void)
{
    char dir[] = "/tmp/vw_obj_input_XXXXXX", path[256], err[512];
    CHECK(mkdtemp(dir) != NULL);
    struct {
        const char *name, *text;
        size_t n;
    } libs[] = {
        {"quiet.mtl", "newmtl red\nKa 0 0 0\nKd 1 0 0\nTf 1 1 1\nsharpness 60\nmap_Kd a.png\n"
                      "map_Bump b.png\nbump b.png\ndisp d.png\ndecal e.png\nrefl -type sphere f.png\n"
                      "Pr 0.5\nPm 0\nPs 0\nPc 0\nPcr 0\naniso 0\nanisor 0\nnorm n.png\n", 0},
        {"vendor.mtl", "newmtl red\nKd 1 0 0\nvendor_thing 3\nKs 0.5 0.5 0.5\nother 1\n", 0},
        {"binary.mtl", "newmtl red\nKd 1 0 0\n# \x1b[2J\n", 0},
    };
    for (size_t i = 0; i < sizeof libs / sizeof libs[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, libs[i].name);
        FILE *f = fopen(path, "wb");
        CHECK(f != NULL);
        CHECK(fwrite(libs[i].text, 1, strlen(libs[i].text), f) == strlen(libs[i].text));
        CHECK(fclose(f) == 0);
    }
    char text[256];
    vw_scene *s;
    int n = snprintf(text, sizeof text, "mtllib quiet.mtl\nusemtl red\n%s", TRI);
    CHECK(read_obj(text, (size_t)n, dir, &s, err, sizeof err) == VW_OK);
    CHECK_EQ_INT(nwarnings, 0);
    vw_scene_free(s);

    /* Two libraries with unknown keywords, one warning each; the OBJ's own is apart. */
    n = snprintf(text, sizeof text, "mtllib vendor.mtl\nmystery\nusemtl red\n%s", TRI);
    CHECK(read_obj(text, (size_t)n, dir, &s, err, sizeof err) == VW_OK);
    CHECK_EQ_INT(nwarnings, 2);
    snprintf(path, sizeof path, "%s/vendor.mtl:3: warning: unknown keyword 'vendor_thing' "
                                "(not an MTL statement)", dir);
    EXPECT(strstr(warnings[0], path) == warnings[0], "'%s'", warnings[0]);
    CHECK(strstr(warnings[1], "t.obj:2: warning: unknown keyword 'mystery' (not an OBJ") ==
          warnings[1]);
    CHECK_NEAR(s->materials[s->polygons[0].material].specular[0], 0.5, 0); /* read on */
    vw_scene_free(s);

    n = snprintf(text, sizeof text, "mtllib binary.mtl\nusemtl red\n%s", TRI);
    CHECK(read_obj(text, (size_t)n, dir, &s, err, sizeof err) == VW_E_INPUT && s == NULL);
    snprintf(path, sizeof path, "%s/binary.mtl:3: control character 0x1b: binary data, not MTL "
                                "text", dir);
    EXPECT(!strcmp(err, path), "'%s'", err);

    for (size_t i = 0; i < sizeof libs / sizeof libs[0]; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, libs[i].name);
        unlink(path);
    }
    rmdir(dir);
}

/* No faces: an empty scene, as vwalls reads an NFF with only its 'v' block and a PLY with
   no faces (the commands render it black); empty input is valid OBJ. */
static void no_faces(void)
{
    accepted("", 0, 0, 0);
    accepted("# nothing\n\n", 11, 0, 0);
    accepted("v 0 0 0\nv 1 0 0\n", 16, 0, 0);
}

/* A DOS end-of-file mark (Ctrl-Z) as the last byte of an OBJ or MTL ends its text (it
   was refused as binary data); anywhere else it is a control character as before. */
static void dos_eof(void)
{
    static const char a[] = "v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n\x1a";
    static const char b[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\x1a";
    accepted(a, sizeof a - 1, 0, 1);
    accepted(b, sizeof b - 1, 0, 1);
    static const char c[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\x1a\n";
    refused(c, sizeof c - 1, "t.obj:4: control character 0x1a: binary data, not OBJ text");
    char dir[] = "/tmp/vw_dos_XXXXXX", path[256], err[512];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/d.mtl", dir);
    FILE *f = fopen(path, "wb");
    CHECK(f != NULL);
    CHECK(fputs("newmtl red\r\nKd 1 0 0\r\n\x1a", f) >= 0);
    CHECK(fclose(f) == 0);
    static const char o[] = "mtllib d.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
    vw_scene *s;
    vw_status st = read_obj(o, sizeof o - 1, dir, &s, err, sizeof err);
    EXPECT(st == VW_OK && nwarnings == 0, "status %d (%s), %d warnings", (int)st, err, nwarnings);
    if (st == VW_OK) {
        CHECK(s->materials[s->polygons[0].material].diffuse[1] == 0.0f);
        vw_scene_free(s);
    }
    remove(path);
    rmdir(dir);
}

int main(void)
{
    vw_scene_set_warning_handler(collect, NULL);
    binary_bytes();
    text_bytes();
    keywords();
    libraries();
    no_faces();
    dos_eof();
    TEST_DONE();
}
