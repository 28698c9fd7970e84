/* test_io_obj.c - the OBJ/MTL reader: face-vertex forms, negative indices, normals,
 * materials from the library, no camera, line continuations, OBJ -> NFF -> scene
 * conversion, and the warnings (tests/data/warn) for a missing library or material and
 * for MTL forms vwalls does not use.
 * Usage: test_io_obj DATA_DIR
 */
#define _GNU_SOURCE
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "io_test_util.h"
#include "vw_test.h"

static int corner(const vw_scene *s, size_t poly, int k)
{
    return s->indices[s->polygons[poly].first + k];
}

/* Warnings the reader gave, collected by the handler. */
static char warnings[16][1024];
static int nwarnings;

static void collect(const char *msg, void *user)
{
    CHECK(user == (void *)warnings);
    if (nwarnings < 16)
        snprintf(warnings[nwarnings], sizeof warnings[0], "%s", msg);
    nwarnings++;
}

/* Does text hold the parts of pattern between "..." in order? */
static int matches(const char *text, const char *pattern)
{
    char part[1024];
    for (const char *p = pattern;;) {
        const char *dots = strstr(p, "...");
        size_t n = dots ? (size_t)(dots - p) : strlen(p);
        snprintf(part, sizeof part, "%.*s", (int)n, p);
        const char *at = strstr(text, part);
        if (!at)
            return 0;
        text = at + n;
        if (!dots)
            return 1;
        p = dots + 3;
    }
}

/* Every file in DATA_DIR/warn is read, with exactly the warnings its first lines
   promise ("# warning: PATTERN", "..." matching anything), in that order. */
static void warn_corpus(const char *data)
{
    const char *names[] = {"obj_missing_mtl.obj", "obj_unknown_usemtl.obj", "mtl_forms.obj",
                           "obj_usemtl_first.obj", "mtl_illum.obj"};
    for (int i = 0; i < 5; i++) {
        char path[4096], line[1024], want[8][1024], err[512] = "";
        int nwant = 0;
        snprintf(path, sizeof path, "%s/warn/%s", data, names[i]);
        FILE *f = fopen(path, "r");
        CHECK(f != NULL);
        while (fgets(line, sizeof line, f) && !strncmp(line, "# warning: ", 11) && nwant < 8) {
            line[strcspn(line, "\n")] = '\0';
            snprintf(want[nwant++], sizeof want[0], "%s", line + 11);
        }
        fclose(f);
        CHECK(nwant > 0);
        nwarnings = 0;
        vw_scene *s = NULL;
        vw_status st = vw_scene_read_file(path, &s, err, sizeof err);
        if (st != VW_OK)
            fprintf(stderr, "%s: %s\n", path, err);
        CHECK_EQ_INT(st, VW_OK);
        for (int k = 0; k < nwarnings && k < 16; k++)
            printf("%s: warning %d: %s\n", names[i], k, warnings[k]);
        CHECK_EQ_INT(nwarnings, nwant);
        for (int k = 0; k < nwant; k++)
            if (!matches(warnings[k], want[k])) {
                fprintf(stderr, "warning %d: '%s'\n  expected '%s'\n", k, warnings[k], want[k]);
                CHECK(0);
            }
        /* mtl_forms.mtl: the statements warned about changed nothing but the dissolve. */
        if (i == 2) {
            const vw_material *m = &s->materials[s->polygons[0].material];
            CHECK(m->diffuse[0] == 0.2f && m->diffuse[1] == 0.4f && m->diffuse[2] == 0.6f);
            CHECK(m->specular[0] == 0.0f && m->transmit == 0.75f);
            vw_scene_free(s);
            continue;
        }
        /* mtl_illum.mtl: an illum out of range leaves the material as without one. */
        if (i == 4) {
            const vw_material *m = &s->materials[s->polygons[0].material];
            CHECK(m->specular[0] == 0.5f && m->reflect[2] == 0.5f && m->ior == 1.5f);
            vw_scene_free(s);
            continue;
        }
        /* Faces of unknown materials get the default 0.8 grey; known ones their own. */
        for (size_t p = 0; p < s->npolygons; p++) {
            const vw_material *m = &s->materials[s->polygons[p].material];
            int red = (i == 1 && p == 1) || (i == 3 && p < 2);
            CHECK(m->diffuse[0] == 0.8f && m->diffuse[1] == (red ? 0.1f : 0.8f));
        }
        vw_scene_free(s);
    }
}

/* What each MTL illumination model gives the ray tracer (obj.c, mtl_apply_illum): Ks
   weights the highlight except for 0 and 1, the mirror ray for 3 to 7 and without an
   illum; Ni refracts for 6 and 7 and without an illum. The statements come in any order
   (illum first for the odd models). The materials go through NFF unchanged. */
static void illum_models(void)
{
    char dir[] = "/tmp/vw_illum_XXXXXX", path[256];
    CHECK(mkdtemp(dir) != NULL);
    snprintf(path, sizeof path, "%s/m.mtl", dir);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    char obj[4096];
    int n = snprintf(obj, sizeof obj, "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
    for (int model = -1; model <= 10; model++) {
        const char *vals = "Ks 0.5 0.25 0.125\nNs 20\nNi 1.5\nd 0.75\n";
        fprintf(f, "newmtl m%d\n", model);
        if (model >= 0 && model % 2)
            fprintf(f, "illum %d\n%s", model, vals);
        else if (model >= 0)
            fprintf(f, "%sillum %d\n", vals, model);
        else
            fprintf(f, "%s", vals);
        n += snprintf(obj + n, sizeof obj - (size_t)n, "usemtl m%d\nf 1 2 3\n", model);
    }
    CHECK(fclose(f) == 0);
    char err[512];
    vw_scene *s;
    vw_status st = vw_scene_read_obj("m.obj", obj, (size_t)n, dir, &s, err, sizeof err);
    if (st != VW_OK)
        fprintf(stderr, "%s\n", err);
    CHECK_EQ_INT(st, VW_OK);
    CHECK_EQ_INT(s->npolygons, 12);
    const float ks[3] = {0.5f, 0.25f, 0.125f};
    for (int model = -1; model <= 10; model++) {
        const vw_material *m = &s->materials[s->polygons[model + 1].material];
        int highlight = model < 0 || model >= 2;
        int mirror = model < 0 || (model >= 3 && model <= 7);
        int refracts = model < 0 || model == 6 || model == 7;
        for (int k = 0; k < 3; k++) {
            EXPECT(m->specular[k] == (highlight ? ks[k] : 0.0f), "illum %d: specular[%d] %g",
                   model, k, m->specular[k]);
            EXPECT(m->reflect[k] == (mirror ? ks[k] : 0.0f), "illum %d: reflect[%d] %g", model,
                   k, m->reflect[k]);
        }
        EXPECT(m->ior == (refracts ? 1.5f : 1.0f), "illum %d: ior %g", model, m->ior);
        EXPECT(m->transmit == 0.25f && m->shine == 20.0f, "illum %d: transmit %g, shine %g",
               model, m->transmit, m->shine);
    }
    char *w = nff_string(s, NULL);
    CHECK(w != NULL);
    vw_scene *b;
    CHECK_EQ_INT(vw_scene_read_nff("m.nff", w, strlen(w), &b, err, sizeof err), VW_OK);
    CHECK_EQ_INT(b->npolygons, s->npolygons);   /* NFF shares equal materials: by face */
    for (size_t i = 0; i < s->npolygons; i++)
        CHECK(memcmp(&b->materials[b->polygons[i].material],
                     &s->materials[s->polygons[i].material], offsetof(vw_material, line)) == 0);
    vw_scene_free(b);
    free(w);
    vw_scene_free(s);
    remove(path);
    rmdir(dir);
}

static void write_file(const char *dir, const char *name, const char *text)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    CHECK(fputs(text, f) >= 0);
    CHECK(fclose(f) == 0);
}

/* Where each material was defined: the library's path as the reader opened it (one copy
   for all the materials of a library, another library another path), the line of its Kd
   (the reflectance, which the radiosity solver may clamp and names), else of its newmtl,
   and its name. A usemtl before the mtllib gets its place from the newmtl that comes
   later; a name no library defines has a name and no place; the default material
   neither. */
static void material_place(void)
{
    char dir[] = "/tmp/vw_mtlplace_XXXXXX", path[512], err[512];
    CHECK(mkdtemp(dir) != NULL);
    write_file(dir, "a.mtl", "# two materials\n"          /* 1 */
                             "newmtl red\n"               /* 2 */
                             "Ks 0.5 0.5 0.5\n"           /* 3 */
                             "Kd 0.8 0.1 0.1\n"           /* 4 */
                             "newmtl nokd\n"              /* 5 */
                             "Ks 0.1 0.1 0.1\n");         /* 6 */
    write_file(dir, "b.mtl", "newmtl white\n"             /* 1 */
                             "Kd 0.5 0.5 0.5\n"           /* 2: overridden */
                             "\n"                         /* 3 */
                             "Kd \\\n"                    /* 4: continued */
                             "1 1 1\n"                    /* 5 */
                             "Kd spectral white.rfl\n"    /* 6: ignored, with a warning */
                             "newmtl late\n"              /* 7 */
                             "Kd 0.2 0.2 0.2\n");         /* 8 */
    write_file(dir, "m.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
                             "f 1 2 3\n"
                             "usemtl late\nf 1 2 3\n"
                             "mtllib a.mtl b.mtl\n"
                             "usemtl red\nf 1 2 3\n"
                             "usemtl nokd\nf 1 2 3\n"
                             "usemtl white\nf 1 2 3\n"
                             "usemtl ghost\nf 1 2 3\n");
    snprintf(path, sizeof path, "%s/m.obj", dir);
    vw_scene *s = NULL;
    nwarnings = 0;
    vw_status st = vw_scene_read_file(path, &s, err, sizeof err);
    if (st != VW_OK)
        fprintf(stderr, "%s\n", err);
    CHECK_EQ_INT(st, VW_OK);
    CHECK_EQ_INT(s->npolygons, 6);
    CHECK_EQ_INT(nwarnings, 2);   /* Kd spectral, ghost */
    char a_path[600], b_path[600];
    snprintf(a_path, sizeof a_path, "%s/a.mtl", dir);
    snprintf(b_path, sizeof b_path, "%s/b.mtl", dir);
    static const struct { const char *name; int in_b, line; } want[6] = {
        {NULL, -1, 0}, {"late", 1, 8}, {"red", 0, 4}, {"nokd", 0, 5}, {"white", 1, 4},
        {"ghost", -1, 0}};
    for (int i = 0; i < 6; i++) {
        const vw_material *m = &s->materials[s->polygons[i].material];
        const char *file = vw_scene_string(s, m->file), *name = vw_scene_string(s, m->name);
        const char *wfile = want[i].in_b < 0 ? NULL : want[i].in_b ? b_path : a_path;
        EXPECT(m->line == want[i].line, "face %d: line %d, want %d", i, m->line, want[i].line);
        EXPECT(wfile ? file && !strcmp(file, wfile) : !file, "face %d: file '%s', want '%s'", i,
               file ? file : "(none)", wfile ? wfile : "(none)");
        EXPECT(want[i].name ? name && !strcmp(name, want[i].name) : !name,
               "face %d: name '%s', want '%s'", i, name ? name : "(none)",
               want[i].name ? want[i].name : "(none)");
    }
    /* One string per library, however many materials it defines; the OBJ's own name
       is not one (no material is defined there). */
    const vw_material *red = &s->materials[s->polygons[2].material];
    const vw_material *nokd = &s->materials[s->polygons[3].material];
    const vw_material *white = &s->materials[s->polygons[4].material];
    CHECK(red->file == nokd->file && red->file != white->file);
    CHECK_EQ_INT(s->nstrings, 2 + 5);   /* a.mtl, b.mtl; late, ghost, red, nokd, white */
    CHECK(white->diffuse[0] == 1.0f && red->diffuse[1] == 0.1f);
    /* The same scene from another directory differs only where it came from. */
    vw_scene *t = NULL;
    char *text = NULL;
    size_t len = 0;
    text = slurp(path, &len);
    CHECK(text != NULL);
    CHECK_EQ_INT(vw_scene_read_obj("m.obj", text, len, dir, &t, err, sizeof err), VW_OK);
    CHECK(scene_equal(s, t) && vw_scene_fingerprint(s) == vw_scene_fingerprint(t));
    free(text);
    vw_scene_free(t);
    vw_scene_free(s);
    const char *names[] = {"a.mtl", "b.mtl", "m.obj"};
    for (int i = 0; i < 3; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        remove(path);
    }
    rmdir(dir);
}

/* cube.obj and cube.mtl with CR (classic Mac OS) or CRLF line ends read as with LF: the
   same scene bit for bit, so the same picture. A CR-only OBJ used to read as one
   statement (one vertex, no faces). */
static void cr_line_ends(const char *data, const vw_scene *lf)
{
    char dir[] = "/tmp/vw_cr_XXXXXX", path[4096];
    CHECK(mkdtemp(dir) != NULL);
    for (int crlf = 0; crlf < 2; crlf++) {
        const char *names[] = {"cube.mtl", "cube.obj"};
        char *obj = NULL;
        size_t obj_n = 0;
        for (int i = 0; i < 2; i++) {
            size_t n, m;
            snprintf(path, sizeof path, "%s/good/%s", data, names[i]);
            char *text = slurp(path, &n);
            CHECK(text != NULL && !memchr(text, '\r', n));
            char *t = vw_test_line_ends(text, n, crlf, &m);
            free(text);
            snprintf(path, sizeof path, "%s/%s", dir, names[i]);
            FILE *f = fopen(path, "wb");
            CHECK(f != NULL && fwrite(t, 1, m, f) == m && fclose(f) == 0);
            if (i == 1) {
                obj = t;
                obj_n = m;
            } else {
                free(t);
            }
        }
        char err[512];
        vw_scene *s;
        vw_status st = vw_scene_read_obj("cube.obj", obj, obj_n, dir, &s, err, sizeof err);
        if (st != VW_OK)
            fprintf(stderr, "%s\n", err);
        CHECK_EQ_INT(st, VW_OK);
        EXPECT(scene_equal(lf, s), "cube.obj with %s line ends", crlf ? "CRLF" : "CR");
        vw_scene_free(s);
        free(obj);
        for (int i = 0; i < 2; i++) {
            snprintf(path, sizeof path, "%s/%s", dir, names[i]);
            remove(path);
        }
    }
    rmdir(dir);
}

/* Positive indices number the file's data as a whole: a face may name a vertex, texture
   coordinate or normal defined after it (Assimp and tinyobjloader read such files). One
   the file never defines is the error, at the face's line, with the file's total. */
static void later_references(void)
{
    char err[512];
    vw_scene *s;
    const char *t = "v 0 0 0\nf 1//2 2//1 3//2\nv 1 0 0\nvn 0 0 1\nv 0 1 0\nvn 0 0 -1\n"
                    "f 4/1 -3/1 -2/1\nvt 0 0\nv 1 1 0\n";
    vw_status st = vw_scene_read_obj("l.obj", t, strlen(t), NULL, &s, err, sizeof err);
    if (st != VW_OK)
        fprintf(stderr, "%s\n", err);
    CHECK_EQ_INT(st, VW_OK);
    CHECK_EQ_INT(s->npolygons, 2);
    CHECK(corner(s, 0, 0) == 0 && corner(s, 0, 1) == 1 && corner(s, 0, 2) == 2);
    CHECK(corner(s, 1, 0) == 3 && corner(s, 1, 1) == 0 && corner(s, 1, 2) == 1);
    CHECK_EQ_INT(s->polygons[0].has_normals, 1);
    CHECK(s->normals[0][2] == -1.0 && s->normals[1][2] == 1.0 && s->normals[2][2] == -1.0);
    CHECK_EQ_INT(s->polygons[1].has_normals, 0);
    vw_scene_free(s);
    const char *bad[][2] = {
        {"v 0 0 0\nv 1 0 0\nf 1 2 3\n# 3 is here\nv 0 1 0\nf 1 2 4\nf 1 2 5\n",
         "b.obj:6: vertex index 4 out of range (3 vertices)"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 \\\n 3//2\nvn 0 0 1\n",
         "b.obj:5: normal index 2 out of range (1 normals)"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/2 3/1\nvt 0 0\n",
         "b.obj:4: texture index 2 out of range (1 texture coordinates)"},
        {"v 0 0 0\nf 1 2 3000000000\nv 1 0 0\n",
         "b.obj:2: vertex index 3000000000 out of range (1 vertices)"},
    };
    for (int i = 0; i < 4; i++) {
        st = vw_scene_read_obj("b.obj", bad[i][0], strlen(bad[i][0]), NULL, &s, err, sizeof err);
        CHECK_EQ_INT(st, VW_E_INPUT);
        if (strcmp(err, bad[i][1]))
            fprintf(stderr, "case %d: '%s'\n  expected '%s'\n", i, err, bad[i][1]);
        CHECK(!strcmp(err, bad[i][1]));
    }
}

/* "mtllib my model.mtl": exporters write a library whose name has blanks as it is. A
   line that names a file as a whole is that file; otherwise blanks separate names. A
   library named twice is read once. */
static void library_with_blanks(void)
{
    char dir[] = "/tmp/vw_blank_XXXXXX", path[256];
    CHECK(mkdtemp(dir) != NULL);
    write_file(dir, "my model.mtl", "newmtl blue\nKd 0 0 1\n");
    write_file(dir, "a.mtl", "newmtl red\nKd 1 0 0\n");
    write_file(dir, "b.mtl", "newmtl green\nKd 0 1 0\n");
    const char *t = "mtllib my model.mtl \nmtllib a.mtl  b.mtl # two\nv 0 0 0\nv 1 0 0\n"
                    "v 0 1 0\nusemtl blue\nf 1 2 3\nusemtl red\nf 1 2 3\nusemtl green\nf 1 2 3\n"
                    "mtllib b.mtl\nusemtl green\nf 1 2 3\n";
    char err[512];
    vw_scene *s;
    nwarnings = 0;
    vw_status st = vw_scene_read_obj("m.obj", t, strlen(t), dir, &s, err, sizeof err);
    if (st != VW_OK)
        fprintf(stderr, "%s\n", err);
    CHECK_EQ_INT(st, VW_OK);
    CHECK_EQ_INT(nwarnings, 0);
    CHECK_EQ_INT(s->npolygons, 4);
    const float want[3][3] = {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}};
    for (int i = 0; i < 3; i++)
        CHECK(!memcmp(s->materials[s->polygons[i].material].diffuse, want[i], sizeof want[i]));
    /* A library named again (exporters repeat mtllib before each object) is not read
       again: its materials are in the scene once. */
    CHECK_EQ_INT(s->nmaterials, 3);
    CHECK_EQ_INT(s->polygons[3].material, s->polygons[2].material);
    vw_scene_free(s);
    const char *names[] = {"my model.mtl", "a.mtl", "b.mtl"};
    for (int i = 0; i < 3; i++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        remove(path);
    }
    rmdir(dir);
}

/* A '#' after a blank in a usemtl or newmtl name (known-issues, 26th review): the name is
   the whole rest of the line, as Blender and Assimp read it, so 3ds Max's "Material #1"
   and "Material #2" stay two materials; a name that matches no material whole is tried
   without its comment, so "usemtl red # the red one" finds "newmtl red" (it was a
   material of its own, 0.8 grey, with a warning) and "usemtl green" finds "newmtl green
   # the green one", in either order of usemtl and library. */
static void material_comments(void)
{
    char dir[] = "/tmp/vw_mcomment_XXXXXX", path[256];
    CHECK(mkdtemp(dir) != NULL);
    write_file(dir, "c.mtl", "newmtl red\nKd 1 0 0\nnewmtl green # the green one\nKd 0 1 0\n"
                             "newmtl Material #1\nKd 0 0 1\nnewmtl Material #2\nKd 1 1 0\n");
    const char *t = "usemtl red # before its library\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"
                    "mtllib c.mtl\nusemtl red # the red one\nf 1 2 3\nusemtl green\nf 1 2 3\n"
                    "usemtl Material #1\nf 1 2 3\nusemtl Material #2 \nf 1 2 3\n"
                    "usemtl Material #3\nf 1 2 3\n";
    char err[512];
    vw_scene *s;
    nwarnings = 0;
    vw_status st = vw_scene_read_obj("m.obj", t, strlen(t), dir, &s, err, sizeof err);
    if (st != VW_OK)
        fprintf(stderr, "%s\n", err);
    CHECK_EQ_INT(st, VW_OK);
    for (int k = 0; k < nwarnings && k < 16; k++)
        printf("material_comments: warning %d: %s\n", k, warnings[k]);
    /* Only "Material #3" is not defined: it does not take "Material #1" or "#2". */
    CHECK_EQ_INT(nwarnings, 1);
    CHECK(!strcmp(warnings[0], "m.obj:15: warning: material 'Material #3' is not defined by a "
                               "material library (the default material is used)"));
    CHECK_EQ_INT(s->npolygons, 6);
    const float want[6][3] = {{1, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0},
                              {0.8f, 0.8f, 0.8f}};
    for (int i = 0; i < 6; i++) {
        const float *d = s->materials[s->polygons[i].material].diffuse;
        EXPECT(!memcmp(d, want[i], sizeof want[i]), "face %d: diffuse %g %g %g", i, d[0], d[1], d[2]);
    }
    /* The usemtl before the library and the one after it name one material. */
    CHECK_EQ_INT(s->polygons[0].material, s->polygons[1].material);
    vw_scene_free(s);
    snprintf(path, sizeof path, "%s/c.mtl", dir);
    remove(path);
    rmdir(dir);
}

int main(int argc, char **argv)
{
    CHECK(argc == 2);
    vw_scene_set_warning_handler(collect, warnings);
    char path[4096], err[512] = "";
    snprintf(path, sizeof path, "%s/good/cube.obj", argv[1]);
    vw_scene *s;
    vw_status st = vw_scene_read_file(path, &s, err, sizeof err);
    if (st != VW_OK)
        fprintf(stderr, "%s\n", err);
    CHECK_EQ_INT(st, VW_OK);
    CHECK_EQ_INT(s->camera.valid, 0);
    CHECK_EQ_INT(s->nlights, 0);
    CHECK_EQ_INT(s->nvertices, 8);
    CHECK_EQ_INT(s->npolygons, 7);
    CHECK_EQ_INT(s->nspheres + s->ncones, 0);
    CHECK_EQ_INT(s->nmaterials, 3);   /* red, white, glowing; no default needed */
    for (int i = 0; i < 7; i++)
        CHECK_EQ_INT(s->polygons[i].id, i);
    /* f 1 4 3 2 (quad kept as a polygon) */
    CHECK_EQ_INT(s->polygons[0].count, 4);
    CHECK(corner(s, 0, 0) == 0 && corner(s, 0, 1) == 3 && corner(s, 0, 3) == 1);
    /* v/vt: no normals; v/vt/vn and v//vn: normals */
    CHECK_EQ_INT(s->polygons[1].has_normals, 0);
    CHECK_EQ_INT(s->polygons[2].has_normals, 1);
    CHECK_EQ_INT(s->polygons[3].has_normals, 1);
    CHECK(s->normals[s->polygons[2].first][2] == 1.0);
    CHECK(s->normals[s->polygons[3].first][2] == -1.0);
    /* negative indices: after 8 vertices, -7 -6 -2 -3 are 2 3 7 6 (1-based) */
    CHECK(corner(s, 4, 0) == 1 && corner(s, 4, 1) == 2 && corner(s, 4, 2) == 6 &&
          corner(s, 4, 3) == 5);
    CHECK(corner(s, 6, 1) == 0 && corner(s, 6, 2) == 4);
    /* materials */
    const vw_material *red = &s->materials[s->polygons[0].material];
    const vw_material *white = &s->materials[s->polygons[1].material];
    const vw_material *glow = &s->materials[s->polygons[5].material];
    CHECK(red->diffuse[0] == 0.8f && red->diffuse[1] == 0.1f && red->specular[2] == 0.4f &&
          red->shine == 25.0f);
    CHECK(red->reflect[0] == 0.0f && red->reflect[2] == 0.0f);      /* illum 2: no mirror */
    CHECK(white->diffuse[0] == 0.7f && white->diffuse[2] == 0.7f);   /* "Kd 0.7" = grey */
    CHECK(white->transmit == 0.25f && white->ior == 1.33f);          /* d 0.75 */
    CHECK(glow->emission[0] == 4.0f && glow->emission[2] == 2.0f && glow->transmit == 0.1f);
    double lo[3], hi[3];
    vw_scene_bounds(s, lo, hi);
    CHECK(lo[0] == 0 && lo[1] == 0 && lo[2] == 0 && hi[0] == 1 && hi[1] == 1 && hi[2] == 1);

    cr_line_ends(argv[1], s);

    /* OBJ -> NFF: the camera is invented (valid then), and the geometry and materials,
       including per-channel Ks and Ke, survive; vertices are no longer shared. */
    char *w = nff_string(s, NULL);
    CHECK(w != NULL);
    vw_scene *n;
    st = vw_scene_read_nff("from_obj.nff", w, strlen(w), &n, err, sizeof err);
    if (st != VW_OK)
        fprintf(stderr, "%s\n%s\n", err, w);
    CHECK_EQ_INT(st, VW_OK);
    CHECK_EQ_INT(n->camera.valid, 1);
    CHECK_EQ_INT(n->npolygons, 7);
    CHECK_EQ_INT(n->nmaterials, 3);
    for (int i = 0; i < 3; i++)   /* the values; the NFF's materials are its 'f' lines */
        CHECK(memcmp(&n->materials[i], &s->materials[i], offsetof(vw_material, line)) == 0);
    for (size_t i = 0; i < 7; i++)
        for (int k = 0; k < s->polygons[i].count; k++)
            CHECK(memcmp(n->vertices[corner(n, i, k)], s->vertices[corner(s, i, k)],
                         sizeof n->vertices[0]) == 0);
    vw_scene_free(n);
    free(w);

    /* Without a directory the mtllib is not loaded; faces get the default grey. */
    const char *t = "mtllib nothere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 -1\n";
    CHECK_EQ_INT(vw_scene_read_obj("m.obj", t, strlen(t), NULL, &n, err, sizeof err), VW_OK);
    CHECK_EQ_INT(n->nmaterials, 1);
    CHECK(n->materials[0].diffuse[0] == 0.8f);
    CHECK_EQ_INT(n->polygons[0].line, 6);
    vw_scene_free(n);
    /* A face keeps its statement's first line, continued or not. */
    t = "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 \\\n 3\nf 1 2 3\n";
    CHECK_EQ_INT(vw_scene_read_obj("m.obj", t, strlen(t), NULL, &n, err, sizeof err), VW_OK);
    CHECK(n->npolygons == 2 && n->polygons[0].line == 5 && n->polygons[1].line == 7);
    vw_scene_free(n);
    /* With one, a missing library and a name it would have defined are warnings, once
       each (common OBJ tools read such a mesh; it used to be refused), and the faces
       get the default grey. Without a directory no name is checked. */
    CHECK_EQ_INT(nwarnings, 0);
    t = "mtllib nothere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 -1\nmtllib nothere.mtl\n"
        "usemtl x\nf 1 2 3\nusemtl y\nf 1 2 3\n";
    CHECK_EQ_INT(vw_scene_read_obj("m.obj", t, strlen(t), "/nonexistent", &n, err, sizeof err),
                 VW_OK);
    CHECK_EQ_INT(nwarnings, 3);
    CHECK(!strcmp(warnings[0], "m.obj:1: warning: material library /nonexistent/nothere.mtl: "
                               "cannot open: No such file or directory; its materials are not "
                               "defined (the default material is used)"));
    CHECK(!strcmp(warnings[1], "m.obj:5: warning: material 'x' is not defined by a material "
                               "library (the default material is used)"));
    CHECK(strstr(warnings[2], "m.obj:10: warning: material 'y' is not") == warnings[2]);
    /* Each name has a material of its own, waiting for a newmtl that never came. */
    CHECK_EQ_INT(n->nmaterials, 2);
    CHECK(n->materials[0].diffuse[0] == 0.8f && n->materials[1].diffuse[0] == 0.8f);
    vw_scene_free(n);
    nwarnings = 0;
    warn_corpus(argv[1]);
    illum_models();
    material_place();
    later_references();
    library_with_blanks();
    material_comments();
    /* A library that is there but wrong is still an error. */
    snprintf(path, sizeof path, "%s/bad/obj_mtl_error.obj", argv[1]);
    CHECK_EQ_INT(vw_scene_read_file(path, &n, err, sizeof err), VW_E_INPUT);
    CHECK(strstr(err, "kd_first.mtl:") != NULL);
    /* v/vt/ (a texture index and an empty normal, known-issues, 26th review) reads as
       v/vt, as tinyobjloader and Assimp read it; it was "bad face vertex". v// and
       v/vt/vn/x still are. */
    t = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nf 1/1/ 2/1/ 3/1/\nf 1/1/ 2/1/1 3/1/\n";
    st = vw_scene_read_obj("t.obj", t, strlen(t), NULL, &n, err, sizeof err);
    if (st != VW_OK)
        fprintf(stderr, "%s\n", err);
    CHECK_EQ_INT(st, VW_OK);
    CHECK(n->npolygons == 2 && n->polygons[0].count == 3 && !n->polygons[0].has_normals &&
          !n->polygons[1].has_normals);
    CHECK(corner(n, 0, 0) == 0 && corner(n, 0, 1) == 1 && corner(n, 0, 2) == 2);
    vw_scene_free(n);
    t = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1// 2// 3//\n";
    CHECK_EQ_INT(vw_scene_read_obj("t.obj", t, strlen(t), NULL, &n, err, sizeof err), VW_E_INPUT);
    CHECK(!strcmp(err, "t.obj:4: bad face vertex '1//'"));
    t = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1/ 2/1/ 3/2/\n";
    CHECK_EQ_INT(vw_scene_read_obj("t.obj", t, strlen(t), NULL, &n, err, sizeof err), VW_E_INPUT);
    CHECK(!strcmp(err, "t.obj:5: texture index 2 out of range (1 texture coordinates)"));
    /* Exact message for an index out of range. */
    t = "v 0 0 0\nv 1 0 0\nv 0 1 0\n# comment\nf 1 2 4\n";
    CHECK_EQ_INT(vw_scene_read_obj("r.obj", t, strlen(t), NULL, &n, err, sizeof err), VW_E_INPUT);
    CHECK(!strcmp(err, "r.obj:5: vertex index 4 out of range (3 vertices)"));
    /* A backslash ending a line joins the next one (CRLF too, and at the end of the
       text); a comment ending in one does not; messages name the token's own line. */
    t = "# from C:\\models\\\nv 0 0 \\\n 0\nv 1 0 0\r\nv 1 1 0\nv 0 1 0\n"
        "f 1 2\\\r\n 3 \\\n\\\n 4 \\";
    CHECK_EQ_INT(vw_scene_read_obj("c.obj", t, strlen(t), NULL, &n, err, sizeof err), VW_OK);
    CHECK_EQ_INT(n->nvertices, 4);
    CHECK_EQ_INT(n->npolygons, 1);
    CHECK_EQ_INT(n->polygons[0].count, 4);
    CHECK(corner(n, 0, 0) == 0 && corner(n, 0, 2) == 2 && corner(n, 0, 3) == 3);
    vw_scene_free(n);
    t = "v 0 0 0\nv 1 0 0\nf 1 \\\n 2 \\\n\\\n 3\n";
    CHECK_EQ_INT(vw_scene_read_obj("c.obj", t, strlen(t), NULL, &n, err, sizeof err), VW_E_INPUT);
    CHECK(!strcmp(err, "c.obj:6: vertex index 3 out of range (2 vertices)"));
    t = "v 0 0 \\\n0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1 1\n";
    CHECK_EQ_INT(vw_scene_read_obj("c.obj", t, strlen(t), NULL, &n, err, sizeof err), VW_E_INPUT);
    CHECK(!strcmp(err, "c.obj:6: wrong number of values for 'v'"));
    /* A lone CR ends a line (classic Mac OS), CRLF is one line end, in one file mixed;
       a backslash continues a line before either. */
    t = "v 0 0 0\rv 1 0 0\r\n# comment \\\rv 1 1 0\n\r\nv 0 \\\r1 0\rf 1 2 \\\r\n3 4\r";
    CHECK_EQ_INT(vw_scene_read_obj("c.obj", t, strlen(t), NULL, &n, err, sizeof err), VW_OK);
    CHECK_EQ_INT(n->nvertices, 4);
    CHECK_EQ_INT(n->npolygons, 1);
    CHECK_EQ_INT(n->polygons[0].count, 4);
    CHECK(n->vertices[3][1] == 1.0 && n->vertices[3][2] == 0.0);
    vw_scene_free(n);
    t = "v 0 0 0\rv 1 0 0\r\n\r# comment \\\rf 1 \\\r 2 \\\r\n\\\r 3\r";
    CHECK_EQ_INT(vw_scene_read_obj("c.obj", t, strlen(t), NULL, &n, err, sizeof err), VW_E_INPUT);
    CHECK(!strcmp(err, "c.obj:8: vertex index 3 out of range (2 vertices)"));
    /* Meshes far from the origin, huge or degenerate, still get a usable default
       camera when written as NFF (the reader rejects 'from' equal to 'at'). */
    const char *far[] = {"v 1e20 1e20 1e20\nv 1e20 1e20 1e20\nv 1e20 1e20 1e20\nf 1 2 3\n",
                         "v -3.4e38 0 0\nv 3.4e38 0 0\nv 0 3.4e38 3.4e38\nf 1 2 3\n",
                         "v 0 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3\n",
                         /* at a corner of the float range: no room on the usual side */
                         ("v 3.4e38 -3.4e38 3.4e38\nv 3.4e38 -3.3e38 3.4e38\nv 3.3e38 -3.4e38 3.4e38\n"
                          "f 1 2 3\n")};
    for (int i = 0; i < 4; i++) {
        CHECK_EQ_INT(vw_scene_read_obj("far.obj", far[i], strlen(far[i]), NULL, &n, err,
                                       sizeof err), VW_OK);
        char *fw = nff_string(n, NULL);
        vw_scene *fb;
        st = vw_scene_read_nff("far.nff", fw, strlen(fw), &fb, err, sizeof err);
        if (st != VW_OK)
            fprintf(stderr, "%s\n", err);
        CHECK_EQ_INT(st, VW_OK);
        vw_scene_free(fb);
        vw_scene_free(n);
        free(fw);
    }
    vw_scene_free(s);
    TEST_DONE();
}
