/* ply.c - the PLY reader (the Stanford polygon format, as scanners and mesh tools write
 * it): a header of elements and their properties, then the data, as text or binary of
 * either byte order.
 *
 * Read: the element "vertex" (x, y, z; nx, ny, nz when all three are there: the
 * corners' normals; red, green, blue when all three are there: ushort as 0..65535,
 * other integers as 0..255, floats as 0..1) and the element "face" (its list
 * "vertex_indices" or "vertex_index"; red, green, blue as for vertices). A face's
 * colour is its own, else the mean of its corners' colours, else 0.8 grey, as an OBJ
 * face without a material; equal colours share one material. A face of fewer than 3
 * corners is skipped with a warning. Every other element and property is read past.
 * PLY has no camera and no lights: the commands' defaults apply, as for OBJ.
 * Errors are "file:line: message": the header's line, an ASCII value's line, and for
 * binary data the line of end_header with the element, the record and the byte offset
 * in the message. An ASCII record is one line (a value more or less is that line's
 * error), and non-blank ASCII data after the last element is an error.
 */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/io_internal.h"
#include "vwalls/scene.h"

#define PLY_DEFAULT_REFLECTANCE 0.8f /* as an OBJ face without a material */

enum ptype { T_NONE, T_I8, T_U8, T_I16, T_U16, T_I32, T_U32, T_F32, T_F64 };
enum { F_ASCII, F_LE, F_BE };

typedef struct prop {
    char name[32];
    enum ptype type;  /* the value's type, or a list's items' */
    enum ptype count; /* a list's count type; T_NONE: a scalar */
} prop;

typedef struct elem {
    char name[32];
    int line; /* of its header line */
    uint64_t count;
    prop *props;
    int nprops, cap;
} elem;

typedef struct ply {
    const char *name;
    int file;                     /* name as a string of the scene, for its materials */
    char *err;
    size_t errlen;
    const unsigned char *p, *end; /* what is left to read */
    int line;                     /* of the next header line or ASCII value */
    int last_line;                /* of the last ASCII value read */
    int rec_line;                 /* ASCII: the line of the record being read, 0 between */
    int format;
    int eol;                      /* how the last header line ended: '\n', 'r' (CRLF) or '\r' */
    elem *elems;
    int nelems;
    vw__sb b;
    int default_mat;
    size_t nverts;
    double (*normals)[3]; /* per vertex, when the vertices carry them */
    float (*colors)[3];   /* per vertex, when the vertices carry them */
} ply;

static vw_status fail(ply *P, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static vw_status fail(ply *P, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vw_status st = vw__input_error(P->err, P->errlen, P->name, P->line, fmt, ap);
    va_end(ap);
    return st;
}

static void warn(ply *P, int line, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void warn(ply *P, int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vw__scene_warning(P->name, line, fmt, ap);
    va_end(ap);
}

static vw_status fail_status(ply *P, vw_status st)
{
    if (st == VW_E_NOMEM) {
        vw__errf(P->err, P->errlen, "%s: out of memory", P->name);
        return st;
    }
    return fail(P, "%s", vw_status_message(st));
}

static enum ptype type_of(const char *s, size_t n)
{
    static const struct {
        const char *name;
        enum ptype t;
    } names[] = {{"char", T_I8},    {"int8", T_I8},     {"uchar", T_U8},   {"uint8", T_U8},
                 {"short", T_I16},  {"int16", T_I16},   {"ushort", T_U16}, {"uint16", T_U16},
                 {"int", T_I32},    {"int32", T_I32},   {"uint", T_U32},   {"uint32", T_U32},
                 {"float", T_F32},  {"float32", T_F32}, {"double", T_F64}, {"float64", T_F64}};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strlen(names[i].name) == n && !memcmp(names[i].name, s, n))
            return names[i].t;
    return T_NONE;
}

static int type_size(enum ptype t)
{
    static const int size[] = {0, 1, 1, 2, 2, 4, 4, 4, 8};
    return size[t];
}

static int is_float(enum ptype t) { return t == T_F32 || t == T_F64; }

/* ---- the header ------------------------------------------------------------------ */

/* The next header line (its end: LF, CRLF or CR) split into at most 6 words. Returns
   the number of words, -1 at the end of the file. */
static int header_line(ply *P, const char *w[6], size_t wn[6])
{
    if (P->p >= P->end)
        return -1;
    const unsigned char *s = P->p;
    while (P->p < P->end && *P->p != '\n' && *P->p != '\r')
        P->p++;
    const unsigned char *e = P->p;
    P->eol = 0;
    if (P->p < P->end && *P->p == '\r') {
        P->p++;
        P->eol = '\r';
    }
    if (P->p < P->end && *P->p == '\n') {
        P->p++; /* LF, or the LF of CRLF */
        P->eol = P->eol ? 'r' : '\n';
    }
    int n = 0;
    while (s < e && n < 6) {
        while (s < e && (*s == ' ' || *s == '\t'))
            s++;
        if (s == e)
            break;
        w[n] = (const char *)s;
        while (s < e && *s != ' ' && *s != '\t')
            s++;
        wn[n] = (size_t)((const char *)s - w[n]);
        n++;
    }
    return n;
}

/* A token of the file as messages show it: printable, bounded (files may hold anything). */
static const char *show(const void *s, size_t n, char buf[48])
{
    return vw_text_shown(s, n, VW_SHOWN_NAME, buf, 48);
}

static int word_is(const char *w, size_t n, const char *lit) { return strlen(lit) == n && !memcmp(w, lit, n); }

static vw_status parse_header(ply *P)
{
    char sb[48];
    const char *w[6];
    size_t wn[6];
    P->line = 1;
    int n = header_line(P, w, wn);
    if (n != 1 || !word_is(w[0], wn[0], "ply"))
        return fail(P, "not a PLY file (its first line is not 'ply')");
    int first_eol = P->eol;
    int have_format = 0;
    for (;;) {
        P->line++;
        n = header_line(P, w, wn);
        if (n < 0)
            return fail(P, "the file ends inside the header (no end_header)");
        if (n == 0 || word_is(w[0], wn[0], "comment") || word_is(w[0], wn[0], "obj_info"))
            continue;
        if (word_is(w[0], wn[0], "end_header")) {
            if (n != 1)
                return fail(P, "end_header takes no values");
            if (!have_format)
                return fail(P, "no format line before end_header");
            /* A header of lone CRs (the PLY description ends its lines with a carriage
               return) whose binary data starts with byte 10: that byte is data, not the
               LF of a CRLF. */
            if (P->format != F_ASCII && first_eol == '\r' && P->eol == 'r')
                P->p--;
            return VW_OK;
        }
        if (word_is(w[0], wn[0], "format")) {
            if (have_format)
                return fail(P, "a second format line");
            if (n != 3)
                return fail(P, "format wants 2 values (the format and 1.0), got %d", n - 1);
            if (word_is(w[1], wn[1], "ascii"))
                P->format = F_ASCII;
            else if (word_is(w[1], wn[1], "binary_little_endian"))
                P->format = F_LE;
            else if (word_is(w[1], wn[1], "binary_big_endian"))
                P->format = F_BE;
            else
                return fail(P, "unknown format '%s' (ascii, binary_little_endian or "
                            "binary_big_endian)", show(w[1], wn[1], sb));
            if (!word_is(w[2], wn[2], "1.0"))
                return fail(P, "unknown format version '%s' (1.0)", show(w[2], wn[2], sb));
            have_format = 1;
        } else if (word_is(w[0], wn[0], "element")) {
            if (!have_format)
                return fail(P, "element before the format line");
            if (n != 3)
                return fail(P, "element wants 2 values (a name and a count), got %d", n - 1);
            long long count;
            if (wn[1] >= sizeof P->elems[0].name)
                return fail(P, "element name too long");
            if (!vw__parse_int(w[2], wn[2], 12, &count) || count < 0 || count > 0x7fffffff)
                return fail(P, "bad element count '%s'", show(w[2], wn[2], sb));
            elem *ne = realloc(P->elems, ((size_t)P->nelems + 1) * sizeof *ne);
            if (!ne)
                return fail_status(P, VW_E_NOMEM);
            P->elems = ne;
            elem *e = &P->elems[P->nelems++];
            memset(e, 0, sizeof *e);
            memcpy(e->name, w[1], wn[1]);
            e->line = P->line;
            e->count = (uint64_t)count;
        } else if (word_is(w[0], wn[0], "property")) {
            if (!P->nelems)
                return fail(P, "property before any element");
            elem *e = &P->elems[P->nelems - 1];
            prop pr;
            memset(&pr, 0, sizeof pr);
            size_t nw;
            const char *nm;
            if (n >= 2 && word_is(w[1], wn[1], "list")) {
                if (n != 5)
                    return fail(P, "property list wants 3 values (count type, item type, "
                                "name), got %d", n - 2);
                pr.count = type_of(w[2], wn[2]);
                pr.type = type_of(w[3], wn[3]);
                if (pr.count == T_NONE || is_float(pr.count))
                    return fail(P, "bad list count type '%s' (an integer type)",
                                show(w[2], wn[2], sb));
                if (pr.type == T_NONE)
                    return fail(P, "unknown type '%s'", show(w[3], wn[3], sb));
                nm = w[4], nw = wn[4];
            } else {
                if (n != 3)
                    return fail(P, "property wants 2 values (a type and a name), got %d", n - 1);
                pr.type = type_of(w[1], wn[1]);
                if (pr.type == T_NONE)
                    return fail(P, "unknown type '%s'", show(w[1], wn[1], sb));
                nm = w[2], nw = wn[2];
            }
            if (nw >= sizeof pr.name)
                return fail(P, "property name too long");
            memcpy(pr.name, nm, nw);
            for (int i = 0; i < e->nprops; i++)
                if (!strcmp(e->props[i].name, pr.name))
                    return fail(P, "element %s has two properties named %s", e->name, pr.name);
            if (e->nprops == e->cap) {
                int cap = e->cap ? 2 * e->cap : 8;
                prop *np = realloc(e->props, (size_t)cap * sizeof *np);
                if (!np)
                    return fail_status(P, VW_E_NOMEM);
                e->props = np;
                e->cap = cap;
            }
            e->props[e->nprops++] = pr;
        } else {
            return fail(P, "unknown header keyword '%s'", show(w[0], wn[0], sb));
        }
    }
}

/* ---- the values ------------------------------------------------------------------ */

/* The next value of type t. ASCII: a whitespace-separated token on the current line
   or a later one; binary: type_size(t) bytes in the file's byte order. */
static vw_status value(ply *P, enum ptype t, const char *what, double *out)
{
    char sb[48];
    if (P->format == F_ASCII) {
        for (;;) {
            while (P->p < P->end && (*P->p == ' ' || *P->p == '\t'))
                P->p++;
            if (P->p < P->end && (*P->p == '\n' || *P->p == '\r')) {
                /* A record is one line: read on, its missing values were taken from
                   the next record, which was blamed (or none was, and the vertices
                   were wrong). At the end of the file the record is one the file
                   ends inside, as before. */
                const unsigned char *q = P->p;
                while (P->rec_line && q < P->end && (*q == ' ' || *q == '\t' || *q == '\n' || *q == '\r'))
                    q++;
                if (P->rec_line && q < P->end) {
                    P->line = P->rec_line;
                    return fail(P, "%s: its line ends before its last value (an ASCII record "
                                "is one line)", what);
                }
                if (*P->p == '\r' && P->p + 1 < P->end && P->p[1] == '\n')
                    P->p++;
                P->p++;
                P->line++;
                continue;
            }
            break;
        }
        if (P->p >= P->end) {
            if (P->last_line)
                P->line = P->last_line; /* not the blank lines after it */
            return fail(P, "the file ends inside %s", what);
        }
        P->last_line = P->line;
        if (!P->rec_line)
            P->rec_line = P->line;
        const char *s = (const char *)P->p;
        while (P->p < P->end && *P->p != ' ' && *P->p != '\t' && *P->p != '\n' && *P->p != '\r')
            P->p++;
        size_t n = (size_t)((const char *)P->p - s);
        if (is_float(t)) {
            int r = vw__parse_double(s, n, out);
            if (r < 0)
                return fail(P, "%s: NaN or infinite number '%s'", what, show(s, n, sb));
            if (r == 0)
                return fail(P, "%s: bad number '%s'", what, show(s, n, sb));
            if (fabs(*out) > FLT_MAX)
                return fail(P, "%s: number '%s' out of range (at most %g in size)", what,
                            show(s, n, sb), (double)FLT_MAX);
            return VW_OK;
        }
        long long v;
        if (!vw__parse_int(s, n, 12, &v))
            return fail(P, "%s: bad integer '%s'", what, show(s, n, sb));
        static const long long lo[] = {0, -128, 0, -32768, 0, -2147483648LL, 0};
        static const long long hi[] = {0, 127, 255, 32767, 65535, 2147483647LL, 4294967295LL};
        if (v < lo[t] || v > hi[t])
            return fail(P, "%s: %lld does not fit its type", what, v);
        *out = (double)v;
        return VW_OK;
    }
    int size = type_size(t);
    if ((size_t)(P->end - P->p) < (size_t)size)
        return fail(P, "the binary data ends inside %s", what);
    uint64_t u = 0;
    for (int i = 0; i < size; i++) {
        int k = P->format == F_LE ? i : size - 1 - i;
        u |= (uint64_t)P->p[k] << (8 * i);
    }
    P->p += size;
    switch (t) {
    case T_I8: *out = (int8_t)u; break;
    case T_U8: *out = (uint8_t)u; break;
    case T_I16: *out = (int16_t)u; break;
    case T_U16: *out = (uint16_t)u; break;
    case T_I32: *out = (int32_t)u; break;
    case T_U32: *out = (uint32_t)u; break;
    case T_F32: {
        uint32_t b = (uint32_t)u;
        float f;
        memcpy(&f, &b, sizeof f);
        *out = f;
        break;
    }
    default: {
        double d;
        memcpy(&d, &u, sizeof d);
        *out = d;
        break;
    }
    }
    if (!isfinite(*out))
        return fail(P, "%s: NaN or infinite number", what);
    if (fabs(*out) > FLT_MAX)
        return fail(P, "%s: number %g out of range (at most %g in size)", what, *out, (double)FLT_MAX);
    return VW_OK;
}

/* A list's length (its count type may be signed: a negative one is refused). */
static vw_status list_length(ply *P, const prop *pr, const char *what, double *n)
{
    vw_status st = value(P, pr->count, what, n);
    if (st == VW_OK && *n < 0)
        return fail(P, "%s: list %s has a negative length %.0f", what, pr->name, *n);
    return st;
}

/* A list item handed over by read_record. */
typedef vw_status (*item_fn)(ply *P, void *arg, double x, const char *what);

/* Spaces and tabs, then the end of the line or of the file? */
static int rest_of_line_blank(ply *P)
{
    while (P->p < P->end && (*P->p == ' ' || *P->p == '\t'))
        P->p++;
    return P->p >= P->end || *P->p == '\n' || *P->p == '\r';
}

/* One record of element e: its scalars into vals (NULL: read past), the items of list
   `keep` to fn, every other list read past. In ASCII a record is one line, as the format
   has it and every writer writes it: a value more or less is that line's error, not one
   found records later on another line. */
static vw_status read_record(ply *P, const elem *e, const char *what, double *vals, int keep,
                             item_fn fn, void *arg)
{
    vw_status st = VW_OK;
    double x;
    P->rec_line = 0;
    for (int i = 0; i < e->nprops && st == VW_OK; i++) {
        const prop *pr = &e->props[i];
        if (pr->count == T_NONE) {
            st = value(P, pr->type, what, vals ? &vals[i] : &x);
            continue;
        }
        double cnt;
        st = list_length(P, pr, what, &cnt);
        for (double k = 0; st == VW_OK && k < cnt; k++)
            if ((st = value(P, pr->type, what, &x)) == VW_OK && i == keep)
                st = fn(P, arg, x, what);
    }
    if (st == VW_OK && P->format == F_ASCII && P->rec_line && !rest_of_line_blank(P)) {
        P->line = P->rec_line;
        st = fail(P, "%s: more values on its line than its properties (an ASCII record is one "
                  "line)", what);
    }
    P->rec_line = 0;
    return st;
}

/* ---- the elements ---------------------------------------------------------------- */

static int find_prop(const elem *e, const char *name)
{
    for (int i = 0; i < e->nprops; i++)
        if (!strcmp(e->props[i].name, name))
            return i;
    return -1;
}

/* Where three named scalar properties are (all three, or -1). */
static int find3(const elem *e, const char *a, const char *b, const char *c, int at[3])
{
    at[0] = find_prop(e, a), at[1] = find_prop(e, b), at[2] = find_prop(e, c);
    for (int k = 0; k < 3; k++)
        if (at[k] < 0 || e->props[at[k]].count != T_NONE)
            return 0;
    return 1;
}

/* A colour component: floats 0..1, ushort 0..65535 (16-bit colour, scaled by its
   type's range as Blender's importer does), every other integer type 0..255. */
static vw_status color_value(ply *P, enum ptype t, double v, const char *what, float *out)
{
    double full = is_float(t) ? 1.0 : t == T_U16 ? 65535.0 : 255.0;
    double c = v / full;
    if (!(c >= 0 && c <= 1))
        return fail(P, "%s: colour component %g outside %s", what, v,
                    is_float(t) ? "0..1" : "0..255");
    *out = (float)c;
    return VW_OK;
}

/* The records hold at least this many bytes (binary) or characters (ASCII: a digit and
   a separator a value, the last one's separator aside): a count the rest of the file
   cannot hold is refused before anything is allocated for it. */
static vw_status check_count(ply *P, const elem *e)
{
    uint64_t least = 0;
    for (int i = 0; i < e->nprops; i++) {
        const prop *pr = &e->props[i];
        least += P->format == F_ASCII ? 2 : (uint64_t)type_size(pr->count != T_NONE ? pr->count : pr->type);
    }
    uint64_t left = (uint64_t)(P->end - P->p) + (P->format == F_ASCII);
    if (least && e->count > left / least)
        return fail(P, "the file ends inside element %s (%llu records cannot fit in the %zu bytes "
                    "left)", e->name, (unsigned long long)e->count, (size_t)(P->end - P->p));
    return VW_OK;
}

static vw_status read_vertices(ply *P, const elem *e)
{
    int xyz[3], nrm[3], rgb[3];
    if (!find3(e, "x", "y", "z", xyz)) {
        P->line = e->line;
        return fail(P, "element vertex has no scalar properties x, y and z");
    }
    int has_n = find3(e, "nx", "ny", "nz", nrm), has_c = find3(e, "red", "green", "blue", rgb);
    vw_status st = check_count(P, e);
    if (st != VW_OK)
        return st;
    size_t n = (size_t)e->count;
    if (has_n && !(P->normals = malloc((n ? n : 1) * sizeof *P->normals)))
        return fail_status(P, VW_E_NOMEM);
    if (has_c && !(P->colors = malloc((n ? n : 1) * sizeof *P->colors)))
        return fail_status(P, VW_E_NOMEM);
    double *vals = malloc((size_t)e->nprops * sizeof *vals);
    if (!vals)
        return fail_status(P, VW_E_NOMEM);
    char what[64];
    for (size_t r = 0; r < n && st == VW_OK; r++) {
        snprintf(what, sizeof what, "vertex %zu", r);
        if ((st = read_record(P, e, what, vals, -1, NULL, NULL)) != VW_OK)
            break;
        double v[3] = {vals[xyz[0]], vals[xyz[1]], vals[xyz[2]]};
        int vi;
        if ((st = vw__sb_add_vertex(&P->b, v, &vi)) != VW_OK) {
            st = fail_status(P, st);
            break;
        }
        for (int k = 0; has_n && k < 3; k++)
            P->normals[r][k] = vals[nrm[k]];
        for (int k = 0; has_c && k < 3 && st == VW_OK; k++)
            st = color_value(P, e->props[rgb[k]].type, vals[rgb[k]], what, &P->colors[r][k]);
    }
    free(vals);
    P->nverts = n;
    return st;
}

/* The material of a face of colour rgb (NULL: none, the default grey), defined where the
   colour was: the face's record (P->b.line: its line in ASCII, 0 in binary data). Equal
   colours share a material, which keeps the place of the first face of that colour. */
static vw_status material_of(ply *P, const float rgb[3], int *mat)
{
    vw_material m;
    vw__default_material(&m);
    for (int k = 0; k < 3; k++)
        m.diffuse[k] = rgb ? rgb[k] : PLY_DEFAULT_REFLECTANCE;
    if (rgb) {
        m.file = P->file;
        m.line = P->b.line;
    }
    if (!rgb && P->default_mat >= 0) {
        *mat = P->default_mat;
        return VW_OK;
    }
    vw_status st = vw__sb_intern_material(&P->b, &m, mat);
    if (st == VW_OK && !rgb)
        P->default_mat = *mat;
    return st;
}

/* A face's corners so far, and the sum of their colours. */
typedef struct face_acc {
    int corners;
    float sum[3];
} face_acc;

static vw_status face_corner(ply *P, void *arg, double x, const char *what)
{
    face_acc *a = arg;
    if (x < 0 || x >= (double)P->nverts)
        return fail(P, "%s: vertex index %.0f out of range (%zu vertices)", what, x, P->nverts);
    size_t vi = (size_t)x;
    vw_status st = vw__sb_polygon_corner(&P->b, (int)vi, P->normals ? P->normals[vi] : NULL);
    if (st != VW_OK)
        return fail_status(P, st);
    for (int c = 0; P->colors && c < 3; c++)
        a->sum[c] += P->colors[vi][c];
    a->corners++;
    return VW_OK;
}

static vw_status read_faces(ply *P, const elem *e, int seen_vertices)
{
    int list = find_prop(e, "vertex_indices");
    if (list < 0)
        list = find_prop(e, "vertex_index");
    if (list < 0 || e->props[list].count == T_NONE || is_float(e->props[list].type)) {
        P->line = e->line;
        return fail(P, "element face has no integer list vertex_indices (or vertex_index)");
    }
    if (!seen_vertices && e->count) {
        P->line = e->line;
        return fail(P, "element face comes before element vertex");
    }
    int rgb[3], has_c = find3(e, "red", "green", "blue", rgb);
    vw_status st = check_count(P, e);
    if (st != VW_OK)
        return st;
    double *vals = malloc((size_t)e->nprops * sizeof *vals);
    if (!vals)
        return fail_status(P, VW_E_NOMEM);
    char what[64];
    /* A face of fewer than 3 corners (a face collapsed to an edge or a point) is no
       polygon: it is skipped, as Blender's importer drops it, with one warning for all
       of them at the first one's line (in binary data the line after end_header). */
    uint64_t skipped = 0, first_skipped = 0;
    int skipped_line = 0;
    for (uint64_t r = 0; r < e->count && st == VW_OK; r++) {
        snprintf(what, sizeof what, "face %llu", (unsigned long long)r);
        face_acc acc = {0, {0, 0, 0}};
        vw__sb_polygon_begin(&P->b);
        st = read_record(P, e, what, vals, list, face_corner, &acc);
        P->b.line = P->format == F_ASCII ? P->last_line : 0; /* an ASCII record is a line */
        if (st != VW_OK)
            break;
        if (acc.corners < 3) {
            vw__sb_polygon_drop(&P->b);
            if (!skipped++) {
                first_skipped = r;
                skipped_line = P->format == F_ASCII ? P->last_line : P->line;
            }
            continue;
        }
        float c[3];
        const float *col = NULL;
        if (has_c) {
            for (int k = 0; k < 3 && st == VW_OK; k++)
                st = color_value(P, e->props[rgb[k]].type, vals[rgb[k]], what, &c[k]);
            if (st != VW_OK)
                break;
            col = c;
        } else if (P->colors) {
            for (int k = 0; k < 3; k++)
                c[k] = acc.sum[k] / (float)acc.corners;
            col = c;
        }
        int mat;
        if ((st = material_of(P, col, &mat)) != VW_OK ||
            (st = vw__sb_polygon_end(&P->b, mat, P->normals != NULL)) != VW_OK)
            st = fail_status(P, st);
    }
    free(vals);
    if (st == VW_OK && skipped)
        warn(P, skipped_line, "%llu face%s of fewer than 3 corners skipped (the first: face %llu)",
             (unsigned long long)skipped, skipped > 1 ? "s" : "",
             (unsigned long long)first_skipped);
    return st;
}

/* Reads past an element nobody uses. An element without properties holds no data,
   whatever its count: nothing to read, and no loop over a count the file cannot bound
   (check_count has no least size for it; 2^31 empty records took minutes). */
static vw_status skip_element(ply *P, const elem *e)
{
    vw_status st = check_count(P, e);
    if (e->nprops == 0)
        return st;
    char what[64];
    for (uint64_t r = 0; r < e->count && st == VW_OK; r++) {
        snprintf(what, sizeof what, "%s %llu", e->name, (unsigned long long)r);
        st = read_record(P, e, what, NULL, -1, NULL, NULL);
    }
    return st;
}

static vw_status parse_ply(ply *P)
{
    vw_status st = parse_header(P);
    if (st != VW_OK)
        return st;
    P->line++; /* ASCII values start on the line after end_header */
    if (P->format == F_ASCII)   /* not a DOS end-of-file mark after them */
        P->end = P->p + vw__text_length((const char *)P->p, (size_t)(P->end - P->p));
    int seen_vertices = 0;
    for (int i = 0; i < P->nelems && st == VW_OK; i++) {
        const elem *e = &P->elems[i];
        if (!strcmp(e->name, "vertex")) {
            if (seen_vertices)
                return fail(P, "a second element vertex");
            st = read_vertices(P, e);
            seen_vertices = 1;
        } else if (!strcmp(e->name, "face")) {
            st = read_faces(P, e, seen_vertices);
        } else {
            st = skip_element(P, e);
        }
    }
    if (st == VW_OK && !seen_vertices)
        return fail(P, "no element vertex");
    /* Data after the last element is a header that says less than the file holds (a
       count too small, an element left out): the scene read would be part of it. */
    while (st == VW_OK && P->format == F_ASCII && P->p < P->end) {
        if (rest_of_line_blank(P)) {
            if (P->p >= P->end)
                break;
            if (*P->p == '\r' && P->p + 1 < P->end && P->p[1] == '\n')
                P->p++;
            P->p++;
            P->line++;
            continue;
        }
        return fail(P, "data after the last element (the header's counts say less than the "
                    "file holds)");
    }
    return st;
}

VW_API vw_status vw_scene_read_ply(const char *name, const void *data, size_t len, vw_scene **out,
                                   char *err, size_t errlen)
{
    if (out)
        *out = NULL;
    if (!out || (!data && len)) {
        vw__errf(err, errlen, "vw_scene_read_ply: NULL argument");
        return VW_E_INVAL;
    }
    if (err && errlen)
        err[0] = '\0';
    ply P;
    memset(&P, 0, sizeof P);
    P.name = name ? name : "<ply>";
    P.err = err;
    P.errlen = errlen;
    P.p = data ? data : (const void *)"";
    P.end = P.p + len;
    P.default_mat = -1;
    vw_status st = vw__sb_init(&P.b);
    if (st != VW_OK) {
        vw__errf(err, errlen, "%s: out of memory", P.name);
        return st;
    }
    st = vw__sb_add_string(&P.b, P.name, strlen(P.name), &P.file);
    st = st == VW_OK ? parse_ply(&P) : fail_status(&P, st);
    for (int i = 0; i < P.nelems; i++)
        free(P.elems[i].props);
    free(P.elems);
    free(P.normals);
    free(P.colors);
    if ((st = vw__sb_close(&P.b, st, out)) == VW_OK) (*out)->camera.valid = 0;
    return st;
}
