/* test_io_nff.c - the NFF reader and writer: every entity, token reading (line breaks
 * do not matter), the light intensity rule, ids and bounds, error line numbers,
 * bit-exact write/read round trips, and no crash on any prefix of a valid file.
 * Usage: test_io_nff DATA_DIR
 */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io_test_util.h"
#include "vw_test.h"

/* Rewrites NFF text with different whitespace: mode 0 puts all tokens on one line,
   mode 1 every token on its own line with tabs and CRLF. Plain comments are dropped;
   "#vw" extension comments are line-based by nature and stay lines of their own. */
static char *reflow(const char *text, int mode)
{
    size_t n = strlen(text), o = 0;
    char *out = malloc(3 * n + 16);
    const char *p = text;
    while (*p) {
        const char *eol = strchr(p, '\n');
        if (!eol)
            eol = p + strlen(p);
        const char *q = p;
        while (q < eol && (*q == ' ' || *q == '\t'))
            q++;
        if (!strncmp(q, "#vw", 3)) {
            out[o++] = '\n';
            memcpy(out + o, q, (size_t)(eol - q));
            o += (size_t)(eol - q);
            out[o++] = '\n';
        } else {
            for (const char *r = p; r < eol && *r != '#';) {
                if (*r == ' ' || *r == '\t' || *r == '\r') {
                    r++;
                    continue;
                }
                while (r < eol && *r != ' ' && *r != '\t' && *r != '\r')
                    out[o++] = *r++;
                if (mode == 0) {
                    out[o++] = ' ';
                } else {
                    memcpy(out + o, "\t\r\n", 3);
                    o += 3;
                }
            }
        }
        p = *eol ? eol + 1 : eol;
    }
    out[o] = '\0';
    return out;
}

static vw_scene *read_text(const char *name, const char *text)
{
    char err[512];
    vw_scene *s = NULL;
    vw_status st = vw_scene_read_nff(name, text, strlen(text), &s, err, sizeof err);
    if (st != VW_OK)
        fprintf(stderr, "unexpected error: %s\n", err);
    CHECK_EQ_INT(st, VW_OK);
    return s;
}

/* The text fails with want, and so does it with CR or CRLF line ends (a text that has
   a CR already is read as it is): a lone CR ends a line, CRLF is one line end (every
   error in a CR-only file was named at line 1). */
static void expect_error(const char *text, const char *want)
{
    for (int form = 0; form < (strchr(text, '\r') ? 1 : 3); form++) {
        char err[512] = "", *t = form ? vw_test_line_ends(text, strlen(text), form - 1, NULL) : NULL;
        vw_scene *s = (vw_scene *)1;
        vw_status st = vw_scene_read_nff("t.nff", t ? t : text, strlen(t ? t : text), &s, err,
                                         sizeof err);
        free(t);
        if (st != VW_E_INPUT || s || strcmp(err, want) != 0) {
            fprintf(stderr, "%s line ends: got  '%s' (status %d)\nwant '%s'\n",
                    form == 0 ? "LF" : form == 1 ? "CR" : "CRLF", err, (int)st, want);
            exit(1);
        }
    }
}

#define VIEW "v from 0 -5 0 at 0 0 0 up 0 0 1 angle 45 hither 0.1 resolution 8 8\n"

/* vw_scene_fingerprint: the same text gives the same value; every part of a scene but
   its camera changes it (the commands compare it between MPI processes). */
static void test_fingerprint(void)
{
    static const char *const base =
        "v from 0 -5 0 at 0 0 0 up 0 0 1 angle 45 hither 0.1 resolution 8 8\n"
        "b 0.1 0.2 0.3\nl 1 2 3\nf 0.5 0.5 0.5 1 0 0 0 1\ns 0 0 0 1\nc 0 0 0 1 0 0 1 0.5\n"
        "pp 3\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\np 4\n0 0 2\n1 0 2\n0.5 0.5 2\n0 1 2\n";
    /* Each edit: (text to find, its replacement, 1 when the fingerprint must change). */
    static const struct { const char *from, *to; int changes; } edits[] = {
        {"from 0 -5 0", "from 0 -6 0", 0},     /* the camera is the view's, not the scene's */
        {"resolution 8 8", "resolution 9 9", 0},
        {"b 0.1 0.2 0.3", "b 0.1 0.2 0.4", 1},
        {"l 1 2 3", "l 1 2 3 0.5 0.5 0.5", 1}, /* a light's colour */
        {"l 1 2 3", "l 1 2 3\nl 4 5 6", 1},    /* another light */
        {"f 0.5 0.5 0.5 1", "f 0.5 0.5 0.6 1", 1},
        {"s 0 0 0 1", "s 0 0 0 1.5", 1},
        {"c 0 0 0 1 0 0 1 0.5", "c 0 0 0 1 0 0 1 0.25", 1},
        {"1 0 0 0 0 1", "1 0 0 0 0.1 1", 1},     /* a normal */
        {"0.5 0.5 2", "0.4 0.5 2", 1},           /* an inner vertex: the bounds stay */
    };
    vw_scene *a = read_text("a.nff", base), *b = read_text("b.nff", base);
    uint64_t fa = vw_scene_fingerprint(a);
    CHECK(fa == vw_scene_fingerprint(b));
    CHECK(fa != vw_scene_fingerprint(NULL));
    for (size_t i = 0; i < sizeof edits / sizeof edits[0]; i++) {
        char text[1024];
        const char *at = strstr(base, edits[i].from);
        CHECK(at != NULL);
        snprintf(text, sizeof text, "%.*s%s%s", (int)(at - base), base, edits[i].to,
                 at + strlen(edits[i].from));
        vw_scene *c = read_text("c.nff", text);
        EXPECT((vw_scene_fingerprint(c) != fa) == edits[i].changes, "'%s' -> '%s': the fingerprint "
               "%s", edits[i].from, edits[i].to, edits[i].changes ? "stayed" : "changed");
        vw_scene_free(c);
    }
    vw_scene_free(a);
    vw_scene_free(b);
}

/* vw_text_shown: what messages show of a file's text. Every byte that is not printable
   ASCII, and the quote, becomes '?'; a name is cut at max bytes and marked "..."; a
   buffer too small for the whole cuts it too, the mark included, never overrunning. */
static void test_text_shown(void)
{
    char b[64];
    CHECK(!strcmp(vw_text_shown("plain", 5, 40, b, sizeof b), "plain"));
    CHECK(!strcmp(vw_text_shown("a'b\nc\x7f\xc3", 7, 40, b, sizeof b), "a?b?c??"));
    CHECK(!strcmp(vw_text_shown("abcdef", 6, 4, b, sizeof b), "abcd..."));
    CHECK(!strcmp(vw_text_shown("abcdef", 6, 0, b, sizeof b), "abcdef"));
    CHECK(!strcmp(vw_text_shown("abcd", 2, 0, b, sizeof b), "ab")); /* n bytes, not to NUL */
    char s[8] = {'x', 'x', 'x', 'x', 'x', 'x', 'x', 'x'};
    CHECK(!strcmp(vw_text_shown("abcdefghij", 10, 0, s, 7), "abc...") && s[7] == 'x');
    memset(s, 'x', sizeof s);
    CHECK(!strcmp(vw_text_shown("abcdefghij", 10, 0, s, 3), "ab") && s[3] == 'x');
    CHECK(!strcmp(vw_text_shown("", 0, 40, b, sizeof b), ""));
}

/* A material keeps where it was defined: its 'f' line and the file's name (no name of
   its own: NFF has none). An 'f' no primitive uses leaves no material; one equal to an
   earlier material is that material, with the earlier 'f' line; the default before any
   'f' has no place. The place is not a value: two files of the same text give equal
   scenes, fingerprints and NFF. */
static void test_material_place(void)
{
    static const char *const text =
        VIEW                                              /* 1 */
        "s 0 0 -3 1\n"                                    /* 2: the default material */
        "f 1 0 0 1 0 0 0 1\n"                             /* 3: used by nothing */
        "f 0.5 0.5 0.5 1 0 0 0 1\n#vw Ke 1 1 1\n"         /* 4, 5 */
        "p 3\n0 0 0\n1 0 0\n0 1 0\n"                      /* 6-9 */
        "\n"                                              /* 10 */
        "f\n1 1 1 1 0 5 0 1\n"                            /* 11, 12: the 'f' on line 11 */
        "s 0 0 3 1\n"                                     /* 13 */
        "f 0.5 0.5 0.5 1 0 0 0 1\n#vw Ke 1 1 1\n"         /* 14, 15: as line 4 */
        "s 0 3 0 1\n";                                    /* 16 */
    for (int form = 0; form < 3; form++) {
        char *t = form ? vw_test_line_ends(text, strlen(text), form - 1, NULL) : NULL;
        vw_scene *s = read_text("dir/scene.nff", t ? t : text);
        vw_scene *o = read_text("other.nff", t ? t : text);
        free(t);
        CHECK_EQ_INT(s->nmaterials, 3);
        const vw_material *dflt = &s->materials[s->spheres[0].material];
        const vw_material *grey = &s->materials[s->polygons[0].material];
        const vw_material *white = &s->materials[s->spheres[1].material];
        EXPECT(dflt->line == 0 && dflt->file == 0 && dflt->name == 0,
               "default material: line %d, file %d, name %d", dflt->line, dflt->file, dflt->name);
        EXPECT(grey->line == 4 && white->line == 11, "'f' lines %d and %d, want 4 and 11 (form %d)",
               grey->line, white->line, form);
        CHECK_EQ_INT(s->spheres[2].material, s->polygons[0].material);
        CHECK(vw_scene_string(s, grey->file) && !strcmp(vw_scene_string(s, grey->file), "dir/scene.nff"));
        CHECK_EQ_INT(white->file, grey->file);   /* one copy of the name for all */
        CHECK(vw_scene_string(s, grey->name) == NULL && vw_scene_string(s, white->name) == NULL);
        CHECK(!strcmp(vw_scene_string(o, o->materials[1].file), "other.nff"));
        CHECK(vw_scene_string(s, 0) == NULL && vw_scene_string(s, -1) == NULL &&
              vw_scene_string(s, (int)s->nstrings + 1) == NULL && vw_scene_string(NULL, 1) == NULL);
        CHECK(scene_equal(s, o));
        CHECK(vw_scene_fingerprint(s) == vw_scene_fingerprint(o));
        char *ws = nff_string(s, NULL), *wo = nff_string(o, NULL);
        CHECK(ws && wo && !strcmp(ws, wo));
        /* Read back, the materials are the written file's 'f' lines, values unchanged. */
        vw_scene *back = read_text("back.nff", ws);
        CHECK(scene_equal(s, back));
        for (size_t i = 0; i < back->nmaterials; i++) {
            int ln = back->materials[i].line;
            const char *at = ws;
            for (int l = 1; l < ln && at; l++)
                at = strchr(at, '\n') ? strchr(at, '\n') + 1 : NULL;
            EXPECT(ln > 0 && at && !strncmp(at, "f ", 2), "material %zu: line %d is not an 'f'", i, ln);
        }
        vw_scene_free(back);
        free(ws);
        free(wo);
        vw_scene_free(s);
        vw_scene_free(o);
    }
}

int main(int argc, char **argv)
{
    CHECK(argc == 2);
    char path[4096], err[512];
    snprintf(path, sizeof path, "%s/good/mixed.nff", argv[1]);
    size_t len;
    char *text = slurp(path, &len);
    CHECK(text != NULL);
    vw_scene *s = read_text(path, text);

    /* Every entity of mixed.nff. */
    CHECK_EQ_INT(s->camera.valid, 1);
    CHECK_EQ_INT(s->camera.width, 64);
    CHECK_EQ_INT(s->camera.height, 48);
    CHECK(s->camera.angle == 40.0 && s->camera.hither == 0.01 && s->camera.up[2] == 1.0);
    CHECK(s->camera.from[1] == -6.0 && s->camera.at[2] == 0.5);
    CHECK(s->background[0] == 0.1f && s->background[1] == 0.2f && s->background[2] == 0.3f);
    CHECK_EQ_INT(s->nlights, 2);
    CHECK(s->lights[0].color[0] == (float)(1.0 / sqrt(2.0)));   /* 1/sqrt(#lights) */
    CHECK(s->lights[0].color[2] == s->lights[0].color[0]);
    CHECK(s->lights[1].color[0] == 0.9f && s->lights[1].color[2] == 0.7f);
    CHECK_EQ_INT(s->nspheres, 2);
    CHECK_EQ_INT(s->ncones, 1);
    CHECK_EQ_INT(s->npolygons, 2);
    CHECK_EQ_INT(vw_scene_count_objects(s), 5);
    CHECK_EQ_INT(s->nmaterials, 2);
    /* ids dense, in file order across kinds */
    CHECK_EQ_INT(s->spheres[0].id, 0);
    CHECK_EQ_INT(s->cones[0].id, 1);
    CHECK_EQ_INT(s->polygons[0].id, 2);
    CHECK_EQ_INT(s->polygons[1].id, 3);
    CHECK_EQ_INT(s->spheres[1].id, 4);
    for (int id = 0; id < 5; id++) {
        vw_prim_kind k;
        size_t i;
        CHECK_EQ_INT(vw_scene_find_object(s, id, &k, &i), VW_OK);
    }
    vw_prim_kind kind;
    size_t idx;
    CHECK(vw_scene_find_object(s, 3, &kind, &idx) == VW_OK && kind == VW_PRIM_POLYGON && idx == 1);
    CHECK(vw_scene_find_object(s, 5, &kind, &idx) == VW_E_INVAL);
    /* materials: diffuse = rgb*Kd, specular = Ks, plus the #vw Ke extension */
    const vw_material *m0 = &s->materials[0], *m1 = &s->materials[1];
    CHECK(m0->diffuse[0] == (float)(0.8 * 0.7) && m0->diffuse[1] == (float)(0.2 * 0.7));
    CHECK(m0->specular[0] == 0.3f && m0->specular[2] == 0.3f && m0->shine == 12.0f);
    CHECK(m0->transmit == 0.0f && m0->ior == 1.0f && m0->emission[0] == 0.0f);
    CHECK(m1->diffuse[2] == (float)(0.9 * 0.9) && m1->transmit == 0.4f && m1->ior == 1.5f);
    CHECK(m1->emission[0] == 0.25f && m1->emission[1] == 0.5f && m1->emission[2] == 1.0f);
    CHECK_EQ_INT(s->spheres[0].material, 0);
    CHECK_EQ_INT(s->cones[0].material, 1);
    CHECK_EQ_INT(s->spheres[1].material, 1);
    CHECK(s->cones[0].apex_radius == -0.2 && s->cones[0].base_radius == 0.4);
    CHECK(s->spheres[0].radius == 0.5 && s->spheres[0].center[2] == 0.5);
    /* p without normals, pp with */
    CHECK_EQ_INT(s->polygons[0].count, 4);
    CHECK_EQ_INT(s->polygons[0].has_normals, 0);
    CHECK_EQ_INT(s->polygons[1].count, 3);
    CHECK_EQ_INT(s->polygons[1].has_normals, 1);
    CHECK(s->normals != NULL);
    CHECK(s->normals[s->polygons[1].first + 2][1] == -0.5);
    CHECK(s->vertices[s->indices[s->polygons[1].first + 2]][2] == 1.5);
    /* bounds: plane in xy, cone base disc down to z = -0.4, pp up to z = 1.5 */
    double lo[3], hi[3];
    vw_scene_bounds(s, lo, hi);
    CHECK(lo[0] == -3 && lo[1] == -3 && lo[2] == -0.4 && hi[0] == 3 && hi[1] == 3 && hi[2] == 1.5);
    vw_scene_object_bounds(s, VW_PRIM_SPHERE, 1, lo, hi);
    CHECK_NEAR(lo[0], -1.5, 1e-15);
    CHECK_NEAR(hi[0], -0.9, 1e-15);

    /* Token reading: the same scene with other line breaks parses identically. */
    for (int mode = 0; mode < 2; mode++) {
        char *t2 = reflow(text, mode);
        vw_scene *s2 = read_text("reflowed.nff", t2);
        CHECK(scene_equal(s, s2));
        vw_scene_free(s2);
        free(t2);
    }

    /* Line ends: CR alone (classic Mac OS) or CRLF read like LF. */
    for (int crlf = 0; crlf < 2; crlf++) {
        char *t2 = vw_test_line_ends(text, strlen(text), crlf, NULL);
        vw_scene *s2 = read_text(crlf ? "crlf.nff" : "cr.nff", t2);
        CHECK(scene_equal(s, s2));
        vw_scene_free(s2);
        free(t2);
    }

    /* Round trip: write, read back, compare bit for bit; writing again gives the same
       text. */
    size_t n1 = 0, n2 = 0;
    char *w1 = nff_string(s, &n1);
    CHECK(w1 != NULL);
    vw_scene *back = read_text("written.nff", w1);
    CHECK(scene_equal(s, back));
    char *w2 = nff_string(back, &n2);
    CHECK(n1 == n2 && memcmp(w1, w2, n1) == 0);
    free(w1);
    free(w2);
    vw_scene_free(back);

    /* Numbers that need all 17 digits survive the round trip. */
    {
        const char *t = VIEW "l 0.1 0.30000000000000004 1e-300 0.1 0.2 0.3\n"
                             "f 0.1 0.2 0.3 0.7 0.11 3.0827 0.1 1.33\n"
                             "s 0.1 0.2 0.30000000000000004 0.1\n";
        vw_scene *a = read_text("digits.nff", t);
        char *w = nff_string(a, NULL);
        vw_scene *b = read_text("digits2.nff", w);
        CHECK(scene_equal(a, b));
        CHECK(b->spheres[0].center[2] == 0.30000000000000004 && b->lights[0].pos[2] == 1e-300);
        free(w);
        vw_scene_free(a);
        vw_scene_free(b);
    }

    /* Negative zeros keep their sign through the round trip (found by fuzz_nff: the
       writer compared them with ==, left out the #vw lines, and read back +0). */
    {
        const char *t = VIEW "f 0.2 0.6 0.9 0.9 0.1 300 0.4 5.5\n#vw Ks 0 -0.0 0\n"
                             "#vw Ke -0 0 0\ns -1.2 0.3 0.3 0.3\n";
        vw_scene *a = read_text("zeros.nff", t);
        char *w = nff_string(a, NULL);
        vw_scene *b = read_text("zeros2.nff", w);
        CHECK(scene_equal(a, b));
        CHECK(signbit(b->materials[b->spheres[0].material].specular[1]));
        CHECK(signbit(b->materials[b->spheres[0].material].emission[0]));
        free(w);
        vw_scene_free(a);
        vw_scene_free(b);
    }

    /* NFF's Ks weights highlight and mirror alike: the 'f' and '#vw Ks' set both, '#vw Kr'
       (after them) the mirror weight alone, and the writer gives a mirror weight that
       differs (an MTL illum 2) that line, so it survives the round trip. */
    {
        const char *t = VIEW "f 1 1 1 1 0.25 10 0 1\ns 0 0 0 1\n"
                             "f 1 1 1 1 0.25 10 0 1\n#vw Ks 0.1 0.2 0.3\ns 1 0 0 1\n"
                             "f 1 1 1 1 0.25 10 0 1\n#vw Ks 0.1 0.2 0.3\n#vw Kr 0 0.5 -0\n"
                             "s 2 0 0 1\n";
        vw_scene *a = read_text("kr.nff", t);
        CHECK_EQ_INT(a->nmaterials, 3);
        const vw_material *f0 = &a->materials[0], *f1 = &a->materials[1], *f2 = &a->materials[2];
        CHECK(f0->specular[2] == 0.25f && f0->reflect[0] == 0.25f && f0->reflect[2] == 0.25f);
        CHECK(f1->specular[2] == 0.3f && f1->reflect[0] == 0.1f && f1->reflect[2] == 0.3f);
        CHECK(f2->specular[2] == 0.3f && f2->reflect[0] == 0.0f && f2->reflect[1] == 0.5f &&
              signbit(f2->reflect[2]));
        char *w = nff_string(a, NULL);
        const char *kr = w ? strstr(w, "#vw Kr") : NULL;   /* one, for the third alone */
        CHECK(kr != NULL && strstr(kr + 1, "#vw Kr") == NULL);
        vw_scene *b = read_text("kr2.nff", w);
        CHECK(scene_equal(a, b));
        free(w);
        vw_scene_free(a);
        vw_scene_free(b);
    }

    /* Unused 'f' leaves no material; equal 'f's share one. */
    {
        const char *t = VIEW "f 1 0 0 1 0 0 0 1\nf 0 1 0 1 0 0 0 1\ns 0 0 0 1\n"
                             "f 0 0 1 1 0 0 0 1\ns 1 0 0 1\nf 0 1 0 1 0 0 0 1\ns 2 0 0 1\n";
        vw_scene *a = read_text("mats.nff", t);
        CHECK_EQ_INT(a->nmaterials, 2);
        CHECK_EQ_INT(a->spheres[0].material, 0);
        CHECK_EQ_INT(a->spheres[1].material, 1);
        CHECK_EQ_INT(a->spheres[2].material, 0);
        vw_scene_free(a);
    }

    /* Each object keeps the line it began on (the statement's keyword), however the
       tokens fall on lines, and the camera its 'resolution' line: messages found after
       parsing (the radiosity mesher's, a size the ray tracer refuses) name them. */
    {
        vw_scene *a = read_text("lines.nff", VIEW "s 0 0 0 1\np 3 0 0 0 1 0 0 0 1 0 p 3\n0 0 0\n"
                                                  "1 0 0\n0 1 0\nc 0 0 0 1\n0 0 1 1\n");
        CHECK(a->nspheres == 1 && a->npolygons == 2 && a->ncones == 1);
        CHECK_EQ_INT(a->camera.resolution_line, 1);
        CHECK_EQ_INT(a->spheres[0].line, 2);
        CHECK_EQ_INT(a->polygons[0].line, 3);
        CHECK_EQ_INT(a->polygons[1].line, 3);
        CHECK_EQ_INT(a->cones[0].line, 7);
        vw_scene_free(a);
    }

    /* A negative sphere radius is NFF's "only the inside is visible": kept, bounded by
       its size, and written back as it was read. */
    {
        vw_scene *a = read_text("inside.nff", VIEW "s 1 0 0 -2\n");
        CHECK(a->nspheres == 1 && a->spheres[0].radius == -2.0);
        double lo[3], hi[3];
        vw_scene_bounds(a, lo, hi);
        CHECK(lo[0] == -1 && hi[0] == 3 && lo[2] == -2 && hi[2] == 2);
        char *w = nff_string(a, NULL);
        CHECK(w != NULL);
        vw_scene *b = read_text("inside2.nff", w);
        CHECK(b->nspheres == 1 && b->spheres[0].radius == -2.0);
        vw_scene_free(b);
        free(w);
        vw_scene_free(a);
        expect_error(VIEW "s 0 0 0\n-0\n", "t.nff:2: sphere radius must not be zero");
    }

    /* '#' starts a comment wherever it is seen, also right after a number, as the
       format says; the entity's numbers are read up to it. */
    {
        vw_scene *a = read_text("hash.nff", VIEW "s 0 0 0\n1# the radius\ns 0 0#x\n 0 2\n");
        CHECK(a->nspheres == 2 && a->spheres[0].radius == 1.0 && a->spheres[1].radius == 2.0);
        vw_scene_free(a);
        expect_error(VIEW "s 0 0 0#\n1x\n", "t.nff:3: bad number '1x' in 's'");
    }

    /* hither and resolution may be left out of 'v', as SPD's reader allows; the
       defaults are written back, so the scene reads again. */
    {
        vw_scene *a = read_text("bare.nff", "v from 0 -5 0 at 0 0 0 up 0 0 1 angle 45\n"
                                            "s 0 0 0 1\n");
        CHECK(a->camera.valid && a->camera.hither == 1.0 && a->camera.width == 512 &&
              a->camera.height == 512);
        char *w = nff_string(a, NULL);
        CHECK(w != NULL);
        vw_scene *b = read_text("bare2.nff", w);
        CHECK(a->camera.resolution_line == 0 && b->camera.resolution_line == 8);
        b->camera.resolution_line = 0; /* the writer gives it a line of its own */
        CHECK(memcmp(&a->camera, &b->camera, sizeof a->camera) == 0);
        vw_scene_free(b);
        free(w);
        vw_scene_free(a);
        expect_error("v from 0 -5 0 at 0 0 0 up 0 0 1 hither 1\n", "t.nff:1: 'v' block without 'angle'");
    }

    /* The light rule and the default material (nocolor.nff). */
    snprintf(path, sizeof path, "%s/good/nocolor.nff", argv[1]);
    vw_scene *nc;
    CHECK_EQ_INT(vw_scene_read_file(path, &nc, err, sizeof err), VW_OK);
    CHECK_EQ_INT(nc->nlights, 4);
    for (int i = 0; i < 4; i++)
        for (int k = 0; k < 3; k++)
            CHECK(nc->lights[i].color[k] == 0.5f);
    CHECK_EQ_INT(nc->nmaterials, 1);
    CHECK(nc->materials[0].diffuse[0] == 1.0f && nc->materials[0].specular[0] == 0.0f &&
          nc->materials[0].ior == 1.0f);
    vw_scene_free(nc);

    /* Exact messages and line numbers, also for entities split across lines. */
    expect_error(VIEW "s 0 0\n0\n\n1 foo\n", "t.nff:5: unknown keyword 'foo'");
    /* An entity that runs short is named by its own line, not by the line of the good
       entity whose keyword showed it short. */
    expect_error(VIEW "s 0 0\n0\n\nl 1 1 1\n", "t.nff:2: wrong number of values for 's'");
    expect_error(VIEW "c\n0 0 0 1\n0 0 1\n\nl 1 1 1\n", "t.nff:2: wrong number of values for 'c'");
    expect_error(VIEW "p 4\n0 0 0\n1 0 0\n1 1 0\ns 0 0 0 1\n",
                 "t.nff:2: wrong number of values for 'p'");
    expect_error(VIEW "l 0 0 5 1 1\n\ns 0 0 0 1\n", "t.nff:2: wrong number of values for 'l'");
    expect_error(VIEW "s 0 0\n0\n\nq\n", "t.nff:5: bad number 'q' in 's'");
    expect_error(VIEW "\n\np 3 0 0 0\n1 0 0\n", "t.nff:4: file ends in the middle of 'p'");
    expect_error(VIEW "p -1\n", "t.nff:2: polygon needs at least 3 vertices");
    expect_error(VIEW "p 99999999999\n", "t.nff:2: vertex count 99999999999 out of range in 'p' (3..2147483647)");
    expect_error(VIEW "b 1 2 3e39\n",
                 "t.nff:2: number '3e39' out of range in 'b' (at most 3.40282e+38 in size)");
    expect_error("", "t.nff:1: missing 'v' block (NFF needs a camera)");
    /* Line ends mixed in one file: LF, CR, CRLF, and a comment ended by a lone CR. */
    expect_error(VIEW "s 0 0 0 1\r\ns 0 0 0 1\r# x 1 2\rs 0 0 0 1\nq\n",
                 "t.nff:6: unknown keyword 'q'");
    expect_error(VIEW "s 0 0 0 1\r\r\n\rs 0 0 0\r", "t.nff:5: file ends in the middle of 's'");
    expect_error(VIEW "s 0 0 0 1\n7\n", "t.nff:3: wrong number of values for 's'");
    expect_error(VIEW "s 0 0 0 1\x01\n",
                 "t.nff:2: control character 0x01: binary data, not NFF text");

    /* Every prefix of a valid file either parses or fails cleanly with "name:line:". */
    for (size_t cut = 0; cut <= len; cut++) {
        vw_scene *p = NULL;
        vw_status st = vw_scene_read_nff("cut.nff", text, cut, &p, err, sizeof err);
        CHECK(st == VW_OK || (st == VW_E_INPUT && p == NULL && !strncmp(err, "cut.nff:", 8)));
        vw_scene_free(p);
    }
    /* NULL err is allowed. */
    vw_scene *p = NULL;
    CHECK(vw_scene_read_nff("x", "q", 1, &p, NULL, 0) == VW_E_INPUT && p == NULL);

    /* A stream that cannot take the scene is VW_E_IO, also when the scene is small
       enough to stay in the stream's buffer (a file limited to 100 bytes). */
    FILE *f = tmpfile();
    CHECK(f != NULL);
    struct rlimit rl;
    CHECK(file_size_limit(100, &rl) == 0);
    vw_status wst = vw_scene_write_nff(s, f);
    CHECK(file_size_restore(&rl) == 0);
    fclose(f);
    CHECK_EQ_INT(wst, VW_E_IO);

    vw_scene_free(s);
    free(text);
    test_fingerprint();
    test_material_place();
    test_text_shown();
    TEST_DONE();
}
