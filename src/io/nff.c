/* src/io/nff.c - reader for Eric Haines' Neutral File Format (the SPD scenes).
 *
 * NFF is read as a stream of whitespace-separated tokens, not lines, so an entity
 * split across lines parses exactly like one on a single line; the lexer counts
 * lines (ended by LF, CRLF or a lone CR) only to name them in messages. '#' comments out the rest of its line, also
 * right after a number ("1# radius"): as soon as one is seen, says the format. One
 * extension rides in comments: "#vw Ks r g b", "#vw Kr r g b" and "#vw Ke r g b" set
 * the specular colour (and mirror weight), the mirror weight alone and the emission of
 * the current material (see vw_scene_write_nff), which other NFF readers ignore. NFF's
 * own Ks weights both the highlight and the mirror ray.
 *
 * The file must be text, as an OBJ must: a NUL byte or another control character
 * (anything below 0x20 but tab, LF, VT, FF and CR, and DEL) anywhere, a comment
 * included, is an error at the byte's line, so binary data named as an NFF is refused
 * as such instead of as its first odd token. Bytes from 0x80 up are text (UTF-8 or a
 * legacy code page in comments).
 */
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "io/io_internal.h"

typedef struct token {
    const char *s;
    size_t n;
    int line;
    int ext;    /* a "#vw" comment; s..s+n is the rest of its line */
} token;

typedef struct lexer {
    const char *p, *end;
    int line;
} lexer;

typedef struct nff {
    const char *name;
    int file;               /* name as a string of the scene, for its materials */
    lexer lx;
    char *err;
    size_t errlen;
    vw__sb b;
    /* The current material is interned only when a primitive uses it, so an 'f'
       that no primitive follows leaves no trace in the material table. */
    vw_material cur;
    int cur_index;          /* -1 until interned */
    int have_f;
    unsigned char *nocolor; /* per light: 1 when the file gave no colour */
    size_t nocolor_cap;
    const char *entity;     /* the entity being read, for messages */
    int entity_line;
    int have_v;
} nff;

static int is_space(char c)
{
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

/* Next token: 1, or 0 at the end of the text, or -1 at a byte no text holds
   (vw__is_binary), with lx->p left on it and lx->line its line. Comments are skipped,
   except that a "#vw" comment is returned as an extension token when want_ext is set
   (only where an entity may start; elsewhere it is an ordinary comment). The check
   adds next to nothing to the token loop, which the whole file goes through: a byte
   up to ' ' ends a token anyway, being a blank, a line end or binary; DEL is the one
   more byte to stop at, and only where a token stops is the byte looked at again. */
static int lex_next(lexer *lx, token *t, int want_ext)
{
    for (;;) {
        /* A line ends at LF, at CRLF (one line end) or at a lone CR (classic Mac OS). */
        while (lx->p < lx->end && is_space(*lx->p)) {
            if (*lx->p == '\r' && lx->end - lx->p > 1 && lx->p[1] == '\n')
                lx->p++;
            if (*lx->p == '\n' || *lx->p == '\r')
                lx->line++;
            lx->p++;
        }
        if (lx->p >= lx->end)
            return 0;
        if (*lx->p == '#') {
            const char *q = lx->p, *eol = q;
            while (eol < lx->end && *eol != '\n' && *eol != '\r' &&
                   !vw__is_binary((unsigned char)*eol))
                eol++;
            lx->p = eol;
            if (eol < lx->end && vw__is_binary((unsigned char)*eol))
                return -1;
            if (want_ext && eol - q >= 4 && memcmp(q, "#vw", 3) == 0 && is_space(q[3])) {
                t->s = q + 3;
                t->n = (size_t)(eol - (q + 3));
                t->line = lx->line;
                t->ext = 1;
                return 1;
            }
            continue;
        }
        /* A token ends at a blank, a line end, a '#', or a byte no text holds: every
           byte up to ' ', and DEL. (From 0x80 up, bytes are token bytes.) */
        const char *start = lx->p;
        unsigned char c;
        while (lx->p < lx->end && (c = (unsigned char)*lx->p) > ' ' && c != '#' &&
               c != 0x7f)
            lx->p++;
        if (lx->p < lx->end && vw__is_binary((unsigned char)*lx->p))
            return -1;
        t->s = start;
        t->n = (size_t)(lx->p - start);
        t->line = lx->line;
        t->ext = 0;
        return 1;
    }
}

static int tok_is(const token *t, const char *kw)
{
    size_t n = strlen(kw);
    return !t->ext && t->n == n && memcmp(t->s, kw, n) == 0;
}

static int is_keyword(const token *t)
{
    static const char *const kws[] = {"v", "b", "l", "f", "c", "s", "p", "pp",
                                      "from", "at", "up", "angle", "hither",
                                      "resolution"};
    for (size_t i = 0; i < sizeof kws / sizeof kws[0]; i++)
        if (tok_is(t, kws[i]))
            return 1;
    return 0;
}

/* A printable, bounded copy of a token for messages: files may hold anything. */
static const char *show(const token *t, char buf[48])
{
    return vw_text_shown(t->s, t->n, VW_SHOWN_NAME, buf, 48);
}

static vw_status fail(nff *P, int line, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

static vw_status fail(nff *P, int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vw_status st = vw__input_error(P->err, P->errlen, P->name, line, fmt, ap);
    va_end(ap);
    return st;
}

/* The lexer stopped at a byte no text holds (lex_next returned -1). */
static vw_status binary(nff *P, const lexer *lx)
{
    char b[24];
    return fail(P, lx->line, "%s: binary data, not NFF text",
                vw__binary_name((unsigned char)*lx->p, b));
}

static vw_status fail_status(nff *P, vw_status st)
{
    if (st == VW_E_NOMEM) {
        fail(P, P->entity_line, "out of memory");
        return VW_E_NOMEM;
    }
    fail(P, P->entity_line, "too many objects, vertices or materials");
    return VW_E_LIMIT;
}

/* 1: a finite number; 0: not a number; -1: NaN or infinite. */
static int parse_double(const token *t, double *out)
{
    return t->ext ? 0 : vw__parse_double(t->s, t->n, out);
}

static vw_status read_num(nff *P, double *out)
{
    token t;
    char sb[48];
    int got = lex_next(&P->lx, &t, 0);
    if (got < 0)
        return binary(P, &P->lx);
    if (!got)
        return fail(P, P->entity_line, "file ends in the middle of '%s'", P->entity);
    int r = parse_double(&t, out);
    /* Every number must fit a float, as OBJ's do: Embree keeps geometry in floats, and
       the world box and the walls are computed from the bounds without overflow. */
    if (r == 1 && fabs(*out) > FLT_MAX)
        return fail(P, t.line, "number '%s' out of range in '%s' (at most %g in size)",
                    show(&t, sb), P->entity, (double)FLT_MAX);
    if (r == 1)
        return VW_OK;
    if (r < 0)
        return fail(P, t.line, "NaN or infinite number '%s' in '%s'", show(&t, sb),
                    P->entity);
    /* A keyword: the entity ran short, and the line to name is the entity's own, not
       that of the next entity (a good one) whose keyword was read. */
    if (is_keyword(&t))
        return fail(P, P->entity_line, "wrong number of values for '%s'", P->entity);
    return fail(P, t.line, "bad number '%s' in '%s'", show(&t, sb), P->entity);
}

static vw_status read_nums(nff *P, double *out, int n)
{
    for (int i = 0; i < n; i++) {
        vw_status st = read_num(P, &out[i]);
        if (st != VW_OK)
            return st;
    }
    return VW_OK;
}

/* Colours and material numbers are stored as float: check they fit. */
static vw_status to_float(nff *P, double v, float *out)
{
    if (fabs(v) > FLT_MAX)
        return fail(P, P->lx.line, "number %g out of range in '%s'", v, P->entity);
    *out = (float)v;
    return VW_OK;
}

static vw_status read_floats(nff *P, float *out, int n)
{
    for (int i = 0; i < n; i++) {
        double v;
        vw_status st = read_num(P, &v);
        if (st == VW_OK)
            st = to_float(P, v, &out[i]);
        if (st != VW_OK)
            return st;
    }
    return VW_OK;
}

static vw_status read_int(nff *P, const char *what, long lo, long hi, int *out)
{
    token t;
    char sb[48];
    int got = lex_next(&P->lx, &t, 0);
    if (got < 0)
        return binary(P, &P->lx);
    if (!got)
        return fail(P, P->entity_line, "file ends in the middle of '%s'", P->entity);
    long long vv;
    if (!vw__parse_int(t.s, t.n, 11, &vv)) {
        if (is_keyword(&t))
            return fail(P, P->entity_line, "wrong number of values for '%s'", P->entity);
        return fail(P, t.line, "bad %s '%s' in '%s'", what, show(&t, sb), P->entity);
    }
    long v = (long)vv;
    if (v < lo || v > hi) {
        if (P->entity[0] == 'p' && v < lo)
            return fail(P, t.line, "polygon needs at least 3 vertices");
        return fail(P, t.line, "%s %ld out of range in '%s' (%ld..%ld)", what, v, P->entity,
                    lo, hi);
    }
    *out = (int)v;
    return VW_OK;
}

static void begin(nff *P, const char *entity, int line)
{
    P->entity = entity;
    P->entity_line = line;
    P->b.line = line;
}

/* ---- entities ----------------------------------------------------------------- */

static vw_status parse_view(nff *P)
{
    vw_camera *cam = &P->b.s->camera;
    int view_line = P->entity_line, up_line = 0;
    int have_from = 0, have_at = 0, have_up = 0, have_angle = 0;
    /* Not every NFF writer gives hither and resolution, and SPD's own reader (ReadNFF)
       takes a 'v' block without them: they default to 1 and to vwalls render's
       512x512. from, at, up and angle it requires, and so do we. */
    cam->hither = 1.0;
    cam->width = cam->height = 512;
    for (;;) {
        lexer save = P->lx;
        token t;
        int got = lex_next(&P->lx, &t, 0);
        if (got < 0)
            return binary(P, &P->lx);
        if (!got)
            break;
        vw_status st;
        if (tok_is(&t, "from")) {
            begin(P, "from", t.line);
            st = read_nums(P, cam->from, 3);
            have_from = 1;
        } else if (tok_is(&t, "at")) {
            begin(P, "at", t.line);
            st = read_nums(P, cam->at, 3);
            have_at = 1;
        } else if (tok_is(&t, "up")) {
            begin(P, "up", t.line);
            up_line = t.line;
            st = read_nums(P, cam->up, 3);
            have_up = 1;
        } else if (tok_is(&t, "angle")) {
            begin(P, "angle", t.line);
            st = read_num(P, &cam->angle);
            if (st == VW_OK && !(cam->angle > 0.0 && cam->angle < 180.0))
                st = fail(P, t.line, "angle must be between 0 and 180 degrees");
            have_angle = 1;
        } else if (tok_is(&t, "hither")) {
            begin(P, "hither", t.line);
            st = read_num(P, &cam->hither);
            if (st == VW_OK && cam->hither < 0.0)
                st = fail(P, t.line, "hither must not be negative");
        } else if (tok_is(&t, "resolution")) {
            begin(P, "resolution", t.line);
            cam->resolution_line = t.line;
            st = read_int(P, "resolution", 0, 1L << 20, &cam->width);
            if (st == VW_OK)
                st = read_int(P, "resolution", 0, 1L << 20, &cam->height);
            if (st == VW_OK && (cam->width == 0 || cam->height == 0))
                st = fail(P, t.line, "resolution must not be zero");
        } else {
            P->lx = save;   /* the next entity */
            break;
        }
        if (st != VW_OK)
            return st;
    }
    const char *missing = !have_from ? "from" : !have_at ? "at" : !have_up ? "up"
                        : !have_angle ? "angle" : NULL;
    if (missing)
        return fail(P, view_line, "'v' block without '%s'", missing);
    /* A problem of 'up' alone (vw_camera_problem names it first) is the up line's, where
       the user will look; one of from and at together is the block's. */
    const char *problem = vw_camera_problem(cam);
    if (problem)
        return fail(P, strncmp(problem, "'up'", 4) ? view_line : up_line, "%s", problem);
    cam->valid = 1;
    P->have_v = 1;
    return VW_OK;
}

static vw_status parse_light(nff *P)
{
    double pos[3];
    float col[3] = {1.0f, 1.0f, 1.0f};
    vw_status st = read_nums(P, pos, 3);
    if (st != VW_OK)
        return st;
    /* The colour is optional: look at the next token without consuming it. */
    lexer save = P->lx;
    token t;
    double dummy;
    int got = lex_next(&P->lx, &t, 0);
    if (got < 0)
        return binary(P, &P->lx);
    int has_color = got && parse_double(&t, &dummy) != 0;
    P->lx = save;
    if (has_color && (st = read_floats(P, col, 3)) != VW_OK)
        return st;
    size_t i = P->b.s->nlights;
    if (i + 1 > P->nocolor_cap) {
        size_t ncap = P->nocolor_cap ? P->nocolor_cap * 2 : 16;
        unsigned char *q = realloc(P->nocolor, ncap);
        if (!q)
            return fail_status(P, VW_E_NOMEM);
        P->nocolor = q;
        P->nocolor_cap = ncap;
    }
    P->nocolor[i] = !has_color;
    st = vw__sb_add_light(&P->b, pos, col);
    return st == VW_OK ? VW_OK : fail_status(P, st);
}

static vw_status parse_fill(nff *P)
{
    double v[8];
    vw_status st = read_nums(P, v, 8);
    if (st != VW_OK)
        return st;
    vw_material m;
    vw__default_material(&m);
    for (int k = 0; k < 3; k++)
        if ((st = to_float(P, v[k] * v[3], &m.diffuse[k])) != VW_OK)
            return st;
    if ((st = to_float(P, v[4], &m.specular[0])) != VW_OK ||
        (st = to_float(P, v[5], &m.shine)) != VW_OK ||
        (st = to_float(P, v[6], &m.transmit)) != VW_OK ||
        (st = to_float(P, v[7], &m.ior)) != VW_OK)
        return st;
    m.specular[1] = m.specular[2] = m.specular[0];
    memcpy(m.reflect, m.specular, sizeof m.reflect);
    /* Defined by this 'f' (the #vw lines after it only complete it). */
    m.line = P->entity_line;
    m.file = P->file;
    P->cur = m;
    P->cur_index = -1;
    P->have_f = 1;
    return VW_OK;
}

static vw_status parse_ext(nff *P, const token *t)
{
    /* The extension line is tokenised on its own so it cannot run past its line. Its
       bytes were checked as the comment was read: lex_next cannot return -1 here. */
    nff sub = *P;
    sub.lx.p = t->s;
    sub.lx.end = t->s + t->n;
    token key;
    if (lex_next(&sub.lx, &key, 0) <= 0)
        return VW_OK;
    /* Ks is NFF's Ks per channel, so it sets the mirror weight too; Kr (written after
       it) the mirror weight alone. */
    static const char *const names[] = {"#vw Ks", "#vw Kr", "#vw Ke"};
    float *dst = tok_is(&key, "Ks") ? P->cur.specular
               : tok_is(&key, "Kr") ? P->cur.reflect
               : tok_is(&key, "Ke") ? P->cur.emission : NULL;
    if (!dst)
        return VW_OK;   /* an extension from a later version: a comment to us */
    const char *entity = names[dst == P->cur.specular ? 0 : dst == P->cur.reflect ? 1 : 2];
    if (!P->have_f)
        return fail(P, t->line, "'%s' before any 'f'", entity);
    begin(&sub, entity, t->line);
    float col[3];
    vw_status st = read_floats(&sub, col, 3);
    if (st != VW_OK)
        return st;
    token extra;
    if (lex_next(&sub.lx, &extra, 0) > 0)
        return fail(P, t->line, "wrong number of values for '%s'", sub.entity);
    memcpy(dst, col, sizeof col);
    if (dst == P->cur.specular)
        memcpy(P->cur.reflect, col, sizeof col);
    P->cur_index = -1;
    return VW_OK;
}

static vw_status use_material(nff *P, int *index)
{
    if (P->cur_index < 0) {
        vw_status st = vw__sb_intern_material(&P->b, &P->cur, &P->cur_index);
        if (st != VW_OK)
            return fail_status(P, st);
    }
    *index = P->cur_index;
    return VW_OK;
}

static vw_status parse_sphere(nff *P)
{
    double v[4];
    int mat;
    vw_status st = read_nums(P, v, 4);
    if (st != VW_OK)
        return st;
    /* A negative radius is NFF's sphere whose inside is visible (as a cone's negative
       radii are): kept as given, the sign is the applications' to read. */
    if (v[3] == 0.0)
        return fail(P, P->entity_line, "sphere radius must not be zero");
    if ((st = use_material(P, &mat)) != VW_OK)
        return st;
    st = vw__sb_add_sphere(&P->b, mat, v, v[3]);
    return st == VW_OK ? VW_OK : fail_status(P, st);
}

static vw_status parse_cone(nff *P)
{
    double v[8];
    int mat;
    vw_status st = read_nums(P, v, 8);
    if (st != VW_OK)
        return st;
    if (v[0] == v[4] && v[1] == v[5] && v[2] == v[6])
        return fail(P, P->entity_line, "cone base and apex are the same point");
    if (v[3] == 0.0 && v[7] == 0.0)
        return fail(P, P->entity_line, "cone has zero radius at both ends");
    if ((st = use_material(P, &mat)) != VW_OK)
        return st;
    st = vw__sb_add_cone(&P->b, mat, v, v[3], v + 4, v[7]);
    return st == VW_OK ? VW_OK : fail_status(P, st);
}

static vw_status parse_polygon(nff *P, int with_normals)
{
    int n, mat;
    vw_status st = read_int(P, "vertex count", 3, INT_MAX, &n);
    if (st != VW_OK)
        return st;
    /* Vertices go straight into the scene as they are read: a count that promises
       more than the file holds fails at the end of the text, never by allocating
       for the promise. */
    vw__sb_polygon_begin(&P->b);
    for (int i = 0; i < n; i++) {
        double v[6];
        int vi;
        if ((st = read_nums(P, v, with_normals ? 6 : 3)) != VW_OK)
            return st;
        st = vw__sb_add_vertex(&P->b, v, &vi);
        if (st == VW_OK)
            st = vw__sb_polygon_corner(&P->b, vi, with_normals ? v + 3 : NULL);
        if (st != VW_OK)
            return fail_status(P, st);
    }
    if ((st = use_material(P, &mat)) != VW_OK)
        return st;
    st = vw__sb_polygon_end(&P->b, mat, with_normals);
    return st == VW_OK ? VW_OK : fail_status(P, st);
}

static vw_status parse_all(nff *P)
{
    token t;
    char sb[48];
    const char *last = NULL;
    int got;
    while ((got = lex_next(&P->lx, &t, 1)) > 0) {
        vw_status st;
        if (t.ext) {
            st = parse_ext(P, &t);
        } else if (tok_is(&t, "v")) {
            begin(P, "v", t.line);
            st = parse_view(P);
        } else if (tok_is(&t, "b")) {
            begin(P, "b", t.line);
            st = read_floats(P, P->b.s->background, 3);
        } else if (tok_is(&t, "l")) {
            begin(P, "l", t.line);
            st = parse_light(P);
        } else if (tok_is(&t, "f")) {
            begin(P, "f", t.line);
            st = parse_fill(P);
        } else if (tok_is(&t, "c")) {
            begin(P, "c", t.line);
            st = parse_cone(P);
        } else if (tok_is(&t, "s")) {
            begin(P, "s", t.line);
            st = parse_sphere(P);
        } else if (tok_is(&t, "p")) {
            begin(P, "p", t.line);
            st = parse_polygon(P, 0);
        } else if (tok_is(&t, "pp")) {
            begin(P, "pp", t.line);
            st = parse_polygon(P, 1);
        } else {
            double d;
            int r = parse_double(&t, &d);
            /* A number where an entity should start: the previous entity had more
               values than it takes. */
            if (r != 0 && last)
                return fail(P, t.line, "wrong number of values for '%s'", last);
            if (r != 0)
                return fail(P, t.line, "number '%s' where a keyword was expected",
                            show(&t, sb));
            return fail(P, t.line, "unknown keyword '%s'", show(&t, sb));
        }
        if (st != VW_OK)
            return st;
        if (!t.ext)
            last = P->entity;
        /* After a 'v' block the last entity read was its last line, e.g. 'resolution'. */
    }
    if (got < 0)
        return binary(P, &P->lx);
    /* Named at the file's last line: after a final newline the lexer counts one more,
       a line no editor shows. */
    int last_line = P->lx.line;
    if (last_line > 1 && (P->lx.end[-1] == '\n' || P->lx.end[-1] == '\r'))
        last_line--;
    if (!P->have_v)
        return fail(P, last_line, "missing 'v' block (NFF needs a camera)");
    /* The classic SPD convention: lights without a colour share a total intensity,
       1/sqrt(number of lights) each. It needs the final count, so it is applied
       after the whole file was read. */
    vw_scene *s = P->b.s;
    float dflt = (float)(1.0 / sqrt((double)s->nlights));
    for (size_t i = 0; i < s->nlights; i++)
        if (P->nocolor[i])
            s->lights[i].color[0] = s->lights[i].color[1] = s->lights[i].color[2] = dflt;
    return VW_OK;
}

VW_API vw_status vw_scene_read_nff(const char *name, const char *text, size_t len,
                                   vw_scene **out, char *err, size_t errlen)
{
    if (out)
        *out = NULL;
    if (!out || (!text && len)) {
        vw__errf(err, errlen, "vw_scene_read_nff: NULL argument");
        return VW_E_INVAL;
    }
    nff P;
    memset(&P, 0, sizeof P);
    P.name = name ? name : "<nff>";
    /* Offsetting a null pointer, even by zero, is undefined: use an empty text. */
    const char *t = text ? text : "";
    P.lx.p = t + vw__bom_length(t, len);
    P.lx.end = t + vw__text_length(t, len);
    P.lx.line = 1;
    P.err = err;
    P.errlen = errlen;
    P.cur_index = -1;
    P.entity = "";
    vw__default_material(&P.cur);
    if (err && errlen)
        err[0] = '\0';
    vw_status st = vw__sb_init(&P.b);
    if (st != VW_OK) {
        vw__errf(err, errlen, "%s: out of memory", P.name);
        return st;
    }
    st = vw__sb_add_string(&P.b, P.name, strlen(P.name), &P.file);
    st = st == VW_OK ? parse_all(&P) : fail_status(&P, st);
    free(P.nocolor);
    return vw__sb_close(&P.b, st, out);
}
