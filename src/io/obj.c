/* src/io/obj.c - reader for Wavefront OBJ meshes and their MTL material libraries.
 *
 * OBJ is line-oriented (a line ends at LF, CRLF or a lone CR, as old Mac OS files
 * have it); a backslash that ends a line joins the next one to it (the OBJ and MTL
 * specifications' continuation), and messages name the physical line of the token
 * they are about. Faces stay polygons (consumers triangulate) over the shared
 * vertex array; a positive index numbers the data of the whole file, so a face may name
 * a vertex, texture coordinate or normal defined after it (checked at the end of the
 * file); texture coordinates, groups, objects and smoothing are accepted and ignored.
 * OBJ has no camera and no lights: camera.valid is 0. A material library
 * that cannot be read and a usemtl name no library defines are warnings (once each),
 * and the faces get the default material, as in common OBJ tools.
 *
 * Both files must be text: a line holding a NUL byte or another control character
 * (anything below 0x20 but tab, LF, VT, FF and CR, and DEL) is an error, so binary data
 * named as an OBJ is refused instead of read as nothing. Bytes from 0x80 up are text
 * (UTF-8 or a legacy code page in comments and names). A keyword the format does not
 * define (a vendor extension, or text that is not OBJ at all) is ignored with one
 * warning per file, naming its first such line. A file with no faces is a scene with
 * no objects, as an NFF with only its 'v' block is.
 */
#include <errno.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/io_internal.h"

/* Materials named in MTL files start as 0.8 grey: white (1.0) would reflect all
   light, and a radiosity solution over such a scene never converges. The same grey
   is used for faces before any usemtl. */
#define OBJ_DEFAULT_REFLECTANCE 0.8f

typedef struct span {
    const char *s;
    size_t n;
} span;

typedef struct obj {
    const char *name;     /* file name for messages (the OBJ or the current MTL) */
    int line;             /* the physical line being read, for messages */
    int next_no;          /* the number of the line after the current statement */
    char *err;
    size_t errlen;
    vw__sb b;
    size_t nvt, nvn;
    double (*vn)[3];
    size_t cap_vn;
    char **mat_names;     /* mat_names[i] names scene material mat_ids[i] (the scene's
                             string, which the scene owns) */
    int *mat_ids;
    int *mat_wait;        /* the line of the first usemtl of a name no library has defined
                             yet (its material waits, 0.8 grey, for a newmtl); 0 once it is */
    size_t nnames, cap_names;
    int cur_mat;          /* -1: the default material, created on first use */
    int mtl_file;         /* the library being read, as a string of the scene */
    int default_mat;
    char **warned;        /* what was warned about ("lib PATH", "mat NAME"): once each */
    size_t nwarned, cap_warned;
    int *libs;            /* the libraries read, as strings of the scene */
    size_t nlibs, cap_libs;
    struct later *later;  /* the face references to data defined after them, in file order */
    size_t nlater, cap_later;
} obj;

/* A face's reference (positive: absolute) to a vertex, texture coordinate or normal the
   file had not defined yet: OBJ numbers its data through the whole file, and readers such
   as Assimp and tinyobjloader take data defined after the face. Checked at the end of
   the file; the corner's vertex index is stored as is meanwhile, its normal filled in. */
struct later {
    char kind;            /* 'v', 't' or 'n' */
    int line;             /* the token's physical line, for the message */
    long long v;          /* the index as written */
    size_t slot;          /* 'n': the corner (index into the scene's indices) */
};

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/* The length of the line continuation at s[0..n): a backslash that ends its line (LF,
   CRLF or a lone CR) or the text; 0 when s does not start with one. */
static size_t continuation(const char *s, size_t n)
{
    if (!n || s[0] != '\\')
        return 0;
    if (n == 1 || s[1] == '\n')
        return n == 1 ? 1 : 2;
    if (s[1] == '\r')
        return n >= 3 && s[2] == '\n' ? 3 : 2;
    return 0;
}

/* The end of the physical line that starts at p: its first LF or CR, or end; *next gets
   the start of the line after it. A line ends at LF, at CRLF (one line end, so line
   numbers stay right) or at a lone CR (classic Mac OS files, which would otherwise read
   as one statement). */
static const char *line_end(const char *p, const char *end, const char **next)
{
    const char *q = p;
    while (q < end && *q != '\n' && *q != '\r')
        q++;
    *next = q + (q < end) + (q + 1 < end && q[0] == '\r' && q[1] == '\n');
    return q;
}

/* Next whitespace-separated token of a statement; a '#' starting a token ends it.
   Continuations are blanks between tokens; passing one counts its line in O->line. */
static int next_tok(obj *O, span *line, span *t)
{
    for (;;) {
        size_t c = continuation(line->s, line->n);
        if (c) {
            O->line += c > 1;
            line->s += c;
            line->n -= c;
        } else if (line->n && is_space(*line->s)) {
            line->s++;
            line->n--;
        } else {
            break;
        }
    }
    if (!line->n || *line->s == '#')
        return 0;
    t->s = line->s;
    while (line->n && !is_space(*line->s) && !continuation(line->s, line->n)) {
        line->s++;
        line->n--;
    }
    t->n = (size_t)(line->s - t->s);
    return 1;
}

/* The rest of the line with surrounding blanks removed (material names, file names). */
static span rest_of_line(span line)
{
    while (line.n && is_space(*line.s)) {
        line.s++;
        line.n--;
    }
    while (line.n && is_space(line.s[line.n - 1]))
        line.n--;
    return line;
}

static int span_eq(span a, span b)
{
    return a.n == b.n && memcmp(a.s, b.s, a.n) == 0;
}

static int span_is(span t, const char *kw)
{
    return span_eq(t, (span){kw, strlen(kw)});
}

static const char *show(span t, char buf[48])
{
    return vw_text_shown(t.s, t.n, VW_SHOWN_NAME, buf, 48);
}

static vw_status fail(obj *O, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static vw_status fail(obj *O, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vw_status st = vw__input_error(O->err, O->errlen, O->name, O->line, fmt, ap);
    va_end(ap);
    return st;
}

/* A warning about key (a library or a material name), unless one was given already:
   an OBJ naming a missing material on a thousand faces warns once. */
static vw_status warn_once(obj *O, const char *kind, span key, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

static vw_status warn_once(obj *O, const char *kind, span key, const char *fmt, ...)
{
    size_t kn = strlen(kind);
    for (size_t i = 0; i < O->nwarned; i++)
        if (!strncmp(O->warned[i], kind, kn) && O->warned[i][kn] == ' ' &&
            strlen(O->warned[i] + kn + 1) == key.n && !memcmp(O->warned[i] + kn + 1, key.s, key.n))
            return VW_OK;
    if (O->nwarned == O->cap_warned) {
        size_t ncap = O->cap_warned ? O->cap_warned * 2 : 8;
        char **q = realloc(O->warned, ncap * sizeof *q);
        if (!q)
            return VW_E_NOMEM;
        O->warned = q;
        O->cap_warned = ncap;
    }
    char *copy = malloc(kn + 1 + key.n + 1);
    if (!copy)
        return VW_E_NOMEM;
    memcpy(copy, kind, kn);
    copy[kn] = ' ';
    memcpy(copy + kn + 1, key.s, key.n);
    copy[kn + 1 + key.n] = '\0';
    O->warned[O->nwarned++] = copy;
    va_list ap;
    va_start(ap, fmt);
    vw__scene_warning(O->name, O->line, fmt, ap);
    va_end(ap);
    return VW_OK;
}

static vw_status fail_status(obj *O, vw_status st)
{
    if (st == VW_E_NOMEM) {
        fail(O, "out of memory");
        return VW_E_NOMEM;
    }
    fail(O, "too many vertices, faces or materials");
    return VW_E_LIMIT;
}

static vw_status parse_double(obj *O, span t, double *out)
{
    char sb[48];
    int r = vw__parse_double(t.s, t.n, out);
    if (r == 0)
        return fail(O, "bad number '%s'", show(t, sb));
    if (r < 0)
        return fail(O, "NaN or infinite number '%s'", show(t, sb));
    /* Every number must fit a float: Embree keeps geometry in floats, MTL colours are
       floats, and the world box is computed from the bounds without overflow. */
    if (fabs(*out) > FLT_MAX)
        return fail(O, "number '%s' out of range (at most %g in size)", show(t, sb),
                    (double)FLT_MAX);
    return VW_OK;
}

/* Reads between min and max numbers from the rest of the line; *n gets the count. */
static vw_status read_numbers(obj *O, span *line, const char *key, double *out, int min,
                              int max, int *n)
{
    span t;
    int k = 0;
    while (k < max && next_tok(O, line, &t)) {
        vw_status st = parse_double(O, t, &out[k]);
        if (st != VW_OK)
            return st;
        k++;
    }
    if (k < min)
        return fail(O, "wrong number of values for '%s'", key);
    if (n)
        *n = k;
    return VW_OK;
}

/* ---- MTL ---------------------------------------------------------------------- */

static vw_status mtl_color(obj *O, span *line, const char *key, float col[3])
{
    double v[3];
    int n;
    vw_status st = read_numbers(O, line, key, v, 1, 3, &n);
    if (st != VW_OK)
        return st;
    if (n == 2)
        return fail(O, "wrong number of values for '%s'", key);
    if (n == 1)
        v[1] = v[2] = v[0];   /* "Kd r" means grey */
    for (int k = 0; k < 3; k++)
        col[k] = (float)v[k]; /* in range: parse_double checked */
    return VW_OK;
}

static vw_status mtl_scalar(obj *O, span *line, const char *key, float *out)
{
    double v = 0;
    vw_status st = read_numbers(O, line, key, &v, 1, 1, NULL);
    if (st != VW_OK)
        return st;
    *out = (float)v; /* in range: parse_double checked */
    return VW_OK;
}

/* Is the statement's first argument the word form? Looks without consuming it (nor
   counting the lines of continuations it passes). */
static int mtl_form(obj *O, span line, const char *form)
{
    int saved = O->line;
    span t;
    int is = next_tok(O, &line, &t) && span_is(t, form);
    O->line = saved;
    return is;
}

/* An illum statement's model into *illum. Not an integer is an error; an integer the
   specification does not define (0 to 10) is a warning, once per value, and leaves
   *illum as it was. */
static vw_status mtl_illum(obj *O, span *line, int *illum)
{
    char sb[48];
    span t;
    long long v;
    if (!next_tok(O, line, &t))
        return fail(O, "wrong number of values for 'illum'");
    if (!vw__parse_int(t.s, t.n, 11, &v))
        return fail(O, "bad illumination model '%s'", show(t, sb));
    if (v >= 0 && v <= 10) {
        *illum = (int)v;
        return VW_OK;
    }
    vw_status st = warn_once(O, "illum", t, "'illum %s' is not an illumination model of the "
                             "MTL specification (0 to 10): it is ignored", show(t, sb));
    return st == VW_OK ? VW_OK : fail_status(O, st);
}

/* Gives a material what its illumination model (-1: the material gave none) means to
   the ray tracer, once all its statements are read: they come in any order. The models
   (the MTL specification's list) and what the ray tracer has for them:
     0, 1   colour, no highlight, no reflection (0, constant colour, is lit as 1)
     2      Phong highlight weighted by Ks (10, the shadow matte, is read as 2)
     3      highlight and ray-traced reflection, both weighted by Ks
     4      as 3 for glass: the dissolve (d, Tr) lets light through unbent
     5      as 3 (the Fresnel term is not modelled)
     6, 7   as 3, and the transmitted ray refracts by Ni (7: Fresnel not modelled)
     8, 9   as 2 and 4 without reflection: their mirror is a reflection map, not a
            ray, and vwalls reads no maps (Blender writes 9 for a transparent material)
   Only 6 and 7 refract: any other model's transmitted ray goes straight on (ior 1), a
   dissolve. Without illum, Ks weights highlight and mirror alike and Ni refracts, as
   in NFF (and in vwalls before it read illum). */
static void mtl_apply_illum(vw_material *m, int illum)
{
    int reflects = illum < 0 || (illum >= 3 && illum <= 7);
    int refracts = illum < 0 || illum == 6 || illum == 7;
    if (illum == 0 || illum == 1)
        memset(m->specular, 0, sizeof m->specular);
    if (reflects)
        memcpy(m->reflect, m->specular, sizeof m->reflect);
    else
        memset(m->reflect, 0, sizeof m->reflect);
    if (!refracts)
        m->ior = 1.0f;
}

/* A material named name, 0.8 grey until its statements say otherwise; wait_line is
   the line of a usemtl that names it before any library defined it, else 0. Its file
   and line are its newmtl's, set by the caller (a usemtl defines nothing). */
static vw_status add_named_material(obj *O, span name, int wait_line)
{
    if (O->nnames == O->cap_names) {
        size_t ncap = O->cap_names ? O->cap_names * 2 : 8;
        char **q = realloc(O->mat_names, ncap * sizeof *q);
        if (!q)
            return fail_status(O, VW_E_NOMEM);
        O->mat_names = q;
        int *r = realloc(O->mat_ids, ncap * sizeof *r);
        if (!r)
            return fail_status(O, VW_E_NOMEM);
        O->mat_ids = r;
        r = realloc(O->mat_wait, ncap * sizeof *r);
        if (!r)
            return fail_status(O, VW_E_NOMEM);
        O->mat_wait = r;
        O->cap_names = ncap;
    }
    /* The name is the scene's string (the material's name), kept once for both. */
    vw_material m;
    vw__default_material(&m);
    m.diffuse[0] = m.diffuse[1] = m.diffuse[2] = OBJ_DEFAULT_REFLECTANCE;
    int id;
    vw_status st = vw__sb_add_string(&O->b, name.s, name.n, &m.name);
    if (st == VW_OK)
        st = vw__sb_add_material(&O->b, &m, &id);
    if (st != VW_OK)
        return fail_status(O, st);
    O->mat_names[O->nnames] = O->b.s->strings[m.name - 1];
    O->mat_ids[O->nnames] = id;
    O->mat_wait[O->nnames] = wait_line;
    O->nnames++;
    return VW_OK;
}

/* A material name without the comment a hand-edited file may put after it: the part
   before the first blank followed by '#' ("red # the red one": "red"), blanks around it
   removed; the name as it is when it has no such comment (or the comment would be all
   of it). */
static span without_comment(span name)
{
    for (size_t i = 1; i < name.n; i++)
        if (name.s[i] == '#' && is_space(name.s[i - 1])) {
            span k = rest_of_line((span){name.s, i});
            return k.n ? k : name;
        }
    return name;
}

/* The newest material called name, or -1: a later library's definition of a name
   replaces an earlier one for the usemtl statements after it.
   A name is the rest of its line, blanks and '#' included, as Blender and Assimp read
   it (3ds Max names materials "Material #1"); names are matched whole first. Only when
   no name matches whole does a comment count: a name with one matches a name without
   it ("usemtl red # the red one" finds "newmtl red", and "usemtl red" finds "newmtl red
   # the red one"). Two names both cut at their '#' are never compared, so "Material #2"
   does not find "Material #1". */
static long find_named_material(const obj *O, span name)
{
    for (size_t i = O->nnames; i-- > 0;)
        if (span_is(name, O->mat_names[i]))
            return (long)i;
    span cut = without_comment(name);
    for (size_t i = O->nnames; i-- > 0;) {
        if ((cut.n != name.n && span_is(cut, O->mat_names[i])) ||
            (cut.n == name.n &&
             span_eq(without_comment((span){O->mat_names[i], strlen(O->mat_names[i])}), name)))
            return (long)i;
    }
    return -1;
}

/* The next statement of [*p, end) (without its final newline) into *line: one line,
   and the lines that continuations join to it. A comment line is never continued: a
   comment ending in a backslash (a Windows directory) must not swallow the statement
   after it. O->line becomes the first line's number; 0 at the end of the text. */
static int next_line(obj *O, const char **p, const char *end, span *line)
{
    if (*p >= end)
        return 0;
    O->line = O->next_no++;
    const char *next, *eol = line_end(*p, end, &next), *first = *p;
    while (first < eol && is_space(*first))
        first++;
    /* eol[-1] of an empty continued line is the line end before it, never a backslash. */
    if (!(first < eol && *first == '#'))
        while (eol < end && eol > *p && eol[-1] == '\\') {
            O->next_no++;
            eol = line_end(next, end, &next);
        }
    line->s = *p;
    line->n = (size_t)(eol - *p);
    *p = next;
    return 1;
}

/* Refuses a statement (its continued lines too, comments included) that holds a byte
   no text holds, naming the physical line of that byte; kind is "OBJ" or "MTL". */
static vw_status check_text(obj *O, span line, const char *kind)
{
    int at = O->line;
    for (size_t i = 0; i < line.n; i++) {
        unsigned char c = (unsigned char)line.s[i];
        if (c == '\n' || (c == '\r' && !(i + 1 < line.n && line.s[i + 1] == '\n')))
            at++;   /* a continuation's line end: CRLF counts at its LF */
        else if (vw__is_binary(c)) {
            char b[24];
            O->line = at;
            return fail(O, "%s: binary data, not %s text", vw__binary_name(c, b), kind);
        }
    }
    return VW_OK;
}

/* Warns about an unknown keyword once per file (the file's first one): a vendor's
   extension is no reason to refuse a mesh, but text that is not OBJ at all, read as
   nothing, must not pass unnoticed. */
static vw_status unknown_keyword(obj *O, span key, const char *kind)
{
    char sb[48];
    span file = {O->name, strlen(O->name)};
    vw_status st = warn_once(O, "keyword", file, "unknown keyword '%s' (not an %s statement): "
                             "ignored, as are any others in this file", show(key, sb), kind);
    return st == VW_OK ? VW_OK : fail_status(O, st);
}

/* Is key one of the words of list[0..n)? */
static int span_in(span key, const char *const *list, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (span_is(key, list[i]))
            return 1;
    return 0;
}

/* The MTL statements vwalls ignores without a word: the rest of the MTL specification
   (ambient colour, transmission filter, sharpness, maps) and the extensions exporters
   commonly write (Blender's map_Bump, the physically based Pr, Pm, Ps, Pc, Pcr, aniso,
   anisor, norm and their maps). The ones read are in parse_mtl's own list. */
static const char *const mtl_ignored[] = {
    "Ka", "Tf", "sharpness", "map_Ka", "map_Kd", "map_Ks", "map_Ke", "map_Ns", "map_d",
    "map_Tr", "map_aat", "disp", "decal", "bump", "map_bump", "map_Bump", "refl",
    "Pr", "Pm", "Ps", "Pc", "Pcr", "aniso", "anisor", "norm", "map_Pr", "map_Pm", "map_Ps",
};

/* Every statement of the OBJ specification (version 3.0) that parse_obj does not read:
   texture, free-form geometry, grouping and display statements, accepted and ignored. */
static const char *const obj_ignored[] = {
    "vp", "l", "p", "g", "o", "s", "mg", "call", "csh", "cstype", "deg", "bmat", "step",
    "curv", "curv2", "surf", "parm", "trim", "hole", "scrv", "sp", "end", "con", "lod",
    "maplib", "usemap", "c_interp", "d_interp", "shadow_obj", "trace_obj", "bevel",
    "ctech", "stech",
};

static vw_status parse_mtl(obj *O, const char *text, size_t len)
{
    const char *p = text + vw__bom_length(text, len), *end = text + vw__text_length(text, len);
    vw_material *m = NULL;
    int illum = -1;   /* m's illumination model; -1 until an illum statement gives one */
    O->line = 0;
    O->next_no = 1;
    span line, key;
    while (next_line(O, &p, end, &line)) {
        vw_status st = check_text(O, line, "MTL");
        if (st != VW_OK)
            return st;
        if (!next_tok(O, &line, &key))
            continue;
        if (span_is(key, "newmtl")) {
            span name = rest_of_line(line);
            if (!name.n)
                return fail(O, "'newmtl' without a name");
            /* The material before is complete (and m may move when one is added). */
            if (m)
                mtl_apply_illum(m, illum);
            illum = -1;
            /* A name a usemtl gave before any library defined it: the material its
               faces already use becomes this one. */
            long i = find_named_material(O, name);
            if (i >= 0 && O->mat_wait[i]) {
                O->mat_wait[i] = 0;
                m = &O->b.s->materials[O->mat_ids[i]];
                /* Matched without a comment (find_named_material): the material takes
                   the name its definition gives, which later usemtl lines look up. */
                if (!span_is(name, O->mat_names[i])) {
                    if ((st = vw__sb_add_string(&O->b, name.s, name.n, &m->name)) != VW_OK)
                        return fail_status(O, st);
                    O->mat_names[i] = O->b.s->strings[m->name - 1];
                }
            } else {
                st = add_named_material(O, name, 0);
                if (st != VW_OK)
                    return st;
                m = &O->b.s->materials[O->b.s->nmaterials - 1];
            }
            /* Defined here; a Kd line moves its line there (see below). */
            m->file = O->mtl_file;
            m->line = O->line;
            continue;
        }
        static const char *const known[] = {"Kd", "Ks", "Ke", "Ns", "d", "Tr", "Ni", "illum"};
        const char *k = NULL;
        for (size_t i = 0; i < sizeof known / sizeof known[0]; i++)
            if (span_is(key, known[i]))
                k = known[i];
        if (!k && !span_in(key, mtl_ignored, sizeof mtl_ignored / sizeof mtl_ignored[0])) {
            if ((st = unknown_keyword(O, key, "MTL")) != VW_OK)
                return st;
            continue;
        }
        if (!k)
            continue;   /* Ka, Tf, maps...: not used by vwalls */
        if (!m)
            return fail(O, "'%s' before any 'newmtl'", k);
        float v;
        if (!strcmp(k, "illum")) {
            if ((st = mtl_illum(O, &line, &illum)) != VW_OK)
                return st;
            continue;
        }
        /* Forms of the MTL specification that vwalls has no use for are valid input, not
           errors: "Kd spectral file.rfl [factor]" (a spectral curve) and "Kd xyz x [y z]"
           (CIE XYZ), also for Ks and Ke, leave the colour as it was, and "d -halo f" (a
           dissolve that grows toward the silhouette) is read as "d f", its value where the
           surface faces the eye. A warning says so, once per form. */
        if (k[0] == 'K' && (mtl_form(O, line, "spectral") || mtl_form(O, line, "xyz"))) {
            const char *form = mtl_form(O, line, "xyz") ? "xyz" : "spectral";
            char what[16];
            snprintf(what, sizeof what, "%s %s", k, form);
            span w = {what, strlen(what)};
            st = warn_once(O, "form", w, "'%s' (%s) is not supported: the statement is ignored",
                           what, form[0] == 'x' ? "a CIE XYZ colour" : "a spectral curve");
            if (st != VW_OK)
                return fail_status(O, st);
            continue;
        }
        if (!strcmp(k, "d") && mtl_form(O, line, "-halo")) {
            span halo, w = {"d -halo", 7};
            next_tok(O, &line, &halo);
            if ((st = mtl_scalar(O, &line, "d -halo", &v)) != VW_OK)
                return st;
            m->transmit = 1.0f - v;
            st = warn_once(O, "form", w, "'d -halo' (a dissolve that changes with the view) is "
                           "not supported: it is read as 'd' with its factor");
            if (st != VW_OK)
                return fail_status(O, st);
            continue;
        }
        if (!strcmp(k, "Kd")) {
            /* The line a message about the reflectance (radiosity clamps it) should name:
               the key's own line (a continuation may have moved O->line past it). */
            int kd_line = O->line;
            if ((st = mtl_color(O, &line, k, m->diffuse)) == VW_OK)
                m->line = kd_line;
        } else if (!strcmp(k, "Ks"))
            st = mtl_color(O, &line, k, m->specular);
        else if (!strcmp(k, "Ke"))
            st = mtl_color(O, &line, k, m->emission);
        else if (!strcmp(k, "Ns"))
            st = mtl_scalar(O, &line, k, &m->shine);
        else if (!strcmp(k, "Ni"))
            st = mtl_scalar(O, &line, k, &m->ior);
        else if ((st = mtl_scalar(O, &line, k, &v)) == VW_OK)
            m->transmit = !strcmp(k, "d") ? 1.0f - v : v;   /* d is opacity */
        if (st != VW_OK)
            return st;
    }
    if (m)
        mtl_apply_illum(m, illum);
    return VW_OK;
}

/* The path of library fname of an OBJ in dir (absolute: as it is), malloc'd; NULL when
   out of memory. */
static char *library_path(const char *dir, span fname)
{
    size_t dn = strlen(dir);
    char *path = malloc(dn + fname.n + 2);
    if (!path)
        return NULL;
    if (fname.n && fname.s[0] == '/') {
        memcpy(path, fname.s, fname.n);
        path[fname.n] = '\0';
    } else {
        memcpy(path, dir, dn);
        path[dn] = '/';
        memcpy(path + dn + 1, fname.s, fname.n);
        path[dn + 1 + fname.n] = '\0';
    }
    return path;
}

/* Is the rest of an mtllib line, holding a blank, the name of a file that opens? (No
   continuation, comment or NUL in it: those make it several names, or none.) */
static int library_exists(const char *dir, span whole)
{
    int blank = 0;
    for (size_t i = 0; i < whole.n; i++) {
        char c = whole.s[i];
        if (c == '\n' || c == '\r' || c == '#' || c == '\0')
            return 0;
        blank |= is_space(c);
    }
    if (!blank)
        return 0;
    char *path = library_path(dir, whole);
    FILE *f = path ? fopen(path, "rb") : NULL;
    free(path);
    if (f)
        fclose(f);
    return f != NULL;
}

static vw_status load_mtllib(obj *O, const char *dir, span fname)
{
    char sb[48];
    if (memchr(fname.s, '\0', fname.n))
        return fail(O, "bad material library name '%s'", show(fname, sb));
    char *path = library_path(dir, fname);
    if (!path)
        return fail_status(O, VW_E_NOMEM);
    /* A library read before (exporters repeat mtllib before each object) defines
       nothing new: read again, every material of it would be in the scene twice. */
    for (size_t i = 0; i < O->nlibs; i++)
        if (!strcmp(O->b.s->strings[O->libs[i] - 1], path)) {
            free(path);
            return VW_OK;
        }
    char *text;
    size_t len;
    char why[256] = "";
    vw_status st = vw__read_whole_file(path, &text, &len, why, sizeof why);
    if (st == VW_E_NOMEM) {
        fail(O, "material library %s", why);
        free(path);
        return st;
    }
    if (st != VW_OK) {
        /* Not there (or not readable): the faces that name its materials get the
           default one, as in common OBJ tools; a mesh is still worth showing. */
        span p = {path, strlen(path)};
        st = warn_once(O, "lib", p, "material library %s; its materials are not defined "
                                    "(the default material is used)", why);
        free(path);
        return st == VW_OK ? VW_OK : fail_status(O, st);
    }
    /* The path, kept once in the scene, is the file of every material it defines. */
    int file;
    st = vw__sb_add_string(&O->b, path, strlen(path), &file);
    free(path);
    if (st == VW_OK && O->nlibs == O->cap_libs) {
        size_t ncap = O->cap_libs ? O->cap_libs * 2 : 4;
        int *q = realloc(O->libs, ncap * sizeof *q);
        if (q) {
            O->libs = q;
            O->cap_libs = ncap;
        } else {
            st = VW_E_NOMEM;
        }
    }
    if (st != VW_OK) {
        free(text);
        return fail_status(O, st);
    }
    O->libs[O->nlibs++] = file;
    const char *obj_name = O->name;
    int obj_line = O->line, obj_next = O->next_no;
    O->name = O->b.s->strings[file - 1];
    O->mtl_file = file;
    st = parse_mtl(O, text, len);
    O->name = obj_name;
    O->line = obj_line;
    O->next_no = obj_next;
    O->mtl_file = 0;
    free(text);
    return st;
}

/* ---- OBJ ---------------------------------------------------------------------- */

static vw_status index_range(obj *O, const char *what, long long v, size_t count)
{
    return fail(O, "%s index %lld out of range (%zu %s)", what, v, count,
                !strcmp(what, "vertex") ? "vertices"
                : !strcmp(what, "normal") ? "normals" : "texture coordinates");
}

/* Resolves one OBJ index (1-based, or negative: relative to the end so far). A positive
   index past the data so far is noted in O->later (slot: the corner, for a normal) and
   *out gets it as is: the end of the file checks it. */
static vw_status resolve(obj *O, span t, const char *what, size_t count, size_t slot, int *out)
{
    char sb[48];
    long long v;
    if (!vw__parse_int(t.s, t.n, 15, &v))
        return fail(O, "bad %s index '%s'", what, show(t, sb));
    long long at = v > 0 ? v - 1 : (long long)count + v;
    if (v == 0 || at < 0 || at >= INT_MAX)
        return index_range(O, what, v, count);
    if (at >= (long long)count) {
        if (O->nlater == O->cap_later) {
            size_t ncap = O->cap_later ? O->cap_later * 2 : 16;
            struct later *q = realloc(O->later, ncap * sizeof *q);
            if (!q)
                return fail_status(O, VW_E_NOMEM);
            O->later = q;
            O->cap_later = ncap;
        }
        O->later[O->nlater++] = (struct later){what[0] == 'v' ? 'v' : what[0] == 'n' ? 'n' : 't',
                                               O->line, v, slot};
    }
    *out = (int)at;
    return VW_OK;
}

/* At the end of the file: the references to data defined after their face are to data
   the file has (the first that is not is the error), and the normals are filled in. */
static vw_status resolve_later(obj *O)
{
    const vw_scene *s = O->b.s;
    for (size_t i = 0; i < O->nlater; i++) {
        const struct later *l = &O->later[i];
        const char *what = l->kind == 'v' ? "vertex" : l->kind == 'n' ? "normal" : "texture";
        size_t count = l->kind == 'v' ? s->nvertices : l->kind == 'n' ? O->nvn : O->nvt;
        if ((unsigned long long)l->v > count) {
            O->line = l->line;
            return index_range(O, what, l->v, count);
        }
        if (l->kind == 'n')
            memcpy(s->normals[l->slot], O->vn[l->v - 1], sizeof s->normals[0]);
    }
    return VW_OK;
}

static vw_status parse_face(obj *O, span *line)
{
    char sb[48];
    span t;
    int n = 0, all_normals = 1;
    O->b.line = O->line; /* the statement's first line */
    vw__sb_polygon_begin(&O->b);
    while (next_tok(O, line, &t)) {
        /* v, v/vt, v/vt/ (as v/vt), v//vn or v/vt/vn */
        span part[3] = {{t.s, 0}, {NULL, 0}, {NULL, 0}};
        int np = 1;
        for (size_t i = 0; i < t.n; i++) {
            if (t.s[i] == '/') {
                if (np == 3)
                    return fail(O, "bad face vertex '%s'", show(t, sb));
                part[np].s = t.s + i + 1;
                np++;
            } else {
                part[np - 1].n++;
            }
        }
        int vi, ti, ni = -1;
        size_t slot = O->b.s->nindices;   /* this corner's */
        vw_status st = resolve(O, part[0], "vertex", O->b.s->nvertices, slot, &vi);
        if (st != VW_OK)
            return st;
        if (np >= 2 && part[1].n &&
            (st = resolve(O, part[1], "texture", O->nvt, slot, &ti)) != VW_OK)
            return st;
        if (np == 2 && !part[1].n)
            return fail(O, "bad face vertex '%s'", show(t, sb));
        /* v/vt/ (an empty normal after a texture index) is v/vt: some exporters write
           it, and tinyobjloader and Assimp read it so. v// is still an error. */
        if (np == 3 && !part[2].n && !part[1].n)
            return fail(O, "bad face vertex '%s'", show(t, sb));
        if (np == 3 && part[2].n &&
            (st = resolve(O, part[2], "normal", O->nvn, slot, &ni)) != VW_OK)
            return st;
        if (ni < 0)
            all_normals = 0;
        /* A normal defined later is filled in at the end (resolve_later). */
        static const double none[3] = {0, 0, 0};
        const double *nrm = ni < 0 ? NULL : (size_t)ni < O->nvn ? O->vn[ni] : none;
        st = vw__sb_polygon_corner(&O->b, vi, nrm);
        if (st != VW_OK)
            return fail_status(O, st);
        n++;
    }
    if (n < 3)
        return fail(O, "face needs at least 3 vertices");
    int mat = O->cur_mat;
    if (mat < 0) {
        if (O->default_mat < 0) {
            vw_material m;
            vw__default_material(&m);
            m.diffuse[0] = m.diffuse[1] = m.diffuse[2] = OBJ_DEFAULT_REFLECTANCE;
            vw_status st = vw__sb_add_material(&O->b, &m, &O->default_mat);
            if (st != VW_OK)
                return fail_status(O, st);
        }
        mat = O->default_mat;
    }
    vw_status st = vw__sb_polygon_end(&O->b, mat, all_normals);
    return st == VW_OK ? VW_OK : fail_status(O, st);
}

static vw_status parse_obj(obj *O, const char *text, size_t len, const char *dir)
{
    const char *p = text + vw__bom_length(text, len), *end = text + vw__text_length(text, len);
    span line, key;
    while (next_line(O, &p, end, &line)) {
        vw_status st = check_text(O, line, "OBJ");
        if (st != VW_OK)
            return st;
        if (!next_tok(O, &line, &key))
            continue;
        double v[3];
        if (span_is(key, "v")) {
            int vi;
            /* x y z, then an optional w or r g b that vwalls does not use */
            if ((st = read_numbers(O, &line, "v", v, 3, 3, NULL)) != VW_OK)
                return st;
            if ((st = vw__sb_add_vertex(&O->b, v, &vi)) != VW_OK)
                return fail_status(O, st);
        } else if (span_is(key, "vn")) {
            if ((st = read_numbers(O, &line, "vn", v, 3, 3, NULL)) != VW_OK)
                return st;
            if (O->nvn == O->cap_vn) {
                size_t ncap = O->cap_vn ? O->cap_vn * 2 : 64;
                void *q = realloc(O->vn, ncap * sizeof *O->vn);
                if (!q)
                    return fail_status(O, VW_E_NOMEM);
                O->vn = q;
                O->cap_vn = ncap;
            }
            memcpy(O->vn[O->nvn++], v, sizeof v);
        } else if (span_is(key, "vt")) {
            if ((st = read_numbers(O, &line, "vt", v, 1, 3, NULL)) != VW_OK)
                return st;
            O->nvt++;
        } else if (span_is(key, "f")) {
            if ((st = parse_face(O, &line)) != VW_OK)
                return st;
        } else if (span_is(key, "usemtl")) {
            span name = rest_of_line(line);
            /* The OBJ specification does not order usemtl after the mtllib that defines
               its name: a name not defined yet gets a material of its own, 0.8 grey, that
               a later newmtl of that name fills in. Names still undefined at the end of
               the file keep the grey, with a warning (once a name, at the line that
               first used it): exporters write usemtl without shipping the library often
               enough that refusing the mesh would help nobody. Without a directory no
               library is loaded, on purpose: every face gets the default material. */
            long i = find_named_material(O, name);
            O->cur_mat = i >= 0 ? O->mat_ids[i] : -1;
            if (i < 0 && dir) {
                if ((st = add_named_material(O, name, O->line)) != VW_OK)
                    return st;
                O->cur_mat = O->mat_ids[O->nnames - 1];
            }
        } else if (span_is(key, "mtllib")) {
            span fname;
            if (!dir)
                continue;   /* no directory given: libraries are not loaded */
            /* The specification separates several libraries by blanks, but exporters
               write a name with blanks in it as it is ("mtllib my model.mtl", Blender
               does): a line that names a file as a whole is that file. */
            span whole = rest_of_line(line);
            if (library_exists(dir, whole)) {
                if ((st = load_mtllib(O, dir, whole)) != VW_OK)
                    return st;
                continue;
            }
            while (next_tok(O, &line, &fname))
                if ((st = load_mtllib(O, dir, fname)) != VW_OK)
                    return st;
        } else if (!span_in(key, obj_ignored, sizeof obj_ignored / sizeof obj_ignored[0])) {
            if ((st = unknown_keyword(O, key, "OBJ")) != VW_OK)
                return st;
        }
    }
    vw_status st = resolve_later(O);
    if (st != VW_OK)
        return st;
    for (size_t i = 0; i < O->nnames; i++)
        if (O->mat_wait[i]) {
            char sb[48];
            span name = {O->mat_names[i], strlen(O->mat_names[i])};
            O->line = O->mat_wait[i];
            vw_status st = warn_once(O, "mat", name, "material '%s' is not defined by a "
                                     "material library (the default material is used)",
                                     show(name, sb));
            if (st != VW_OK)
                return fail_status(O, st);
        }
    return VW_OK;
}

VW_API vw_status vw_scene_read_obj(const char *name, const char *text, size_t len,
                                   const char *dir, vw_scene **out, char *err,
                                   size_t errlen)
{
    if (out)
        *out = NULL;
    if (!out || (!text && len)) {
        vw__errf(err, errlen, "vw_scene_read_obj: NULL argument");
        return VW_E_INVAL;
    }
    obj O;
    memset(&O, 0, sizeof O);
    O.name = name ? name : "<obj>";
    O.next_no = 1;
    O.err = err;
    O.errlen = errlen;
    O.cur_mat = -1;
    O.default_mat = -1;
    if (err && errlen)
        err[0] = '\0';
    vw_status st = vw__sb_init(&O.b);
    if (st != VW_OK) {
        vw__errf(err, errlen, "%s: out of memory", O.name);
        return st;
    }
    st = parse_obj(&O, text ? text : "", len, dir);
    free(O.mat_names);
    for (size_t i = 0; i < O.nwarned; i++)
        free(O.warned[i]);
    free(O.warned);
    free(O.mat_ids);
    free(O.mat_wait);
    free(O.vn);
    free(O.later);
    free(O.libs);
    if ((st = vw__sb_close(&O.b, st, out)) == VW_OK) (*out)->camera.valid = 0;
    return st;
}
