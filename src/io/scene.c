/* src/io/scene.c - the in-memory scene: the builder every reader and generator fills,
 * file-level reading (dispatch on extension), the NFF writer, and queries (counts,
 * bounds, lookup by id, a default camera).
 */
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/hash.h"
#include "io/io_internal.h"
#include "vwalls/outfile.h"

void vw__errf(char *err, size_t errlen, const char *fmt, ...)
{
    if (!err || errlen == 0)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
}

int vw__parse_int(const char *s, size_t n, size_t maxlen, long long *out)
{
    size_t i = 0;
    int neg = 0;
    long long v = 0;
    if (n == 0 || n > maxlen) return 0;
    if (s[0] == '-' || s[0] == '+') {
        neg = s[0] == '-';
        if (n == 1) return 0;
        i = 1;
    }
    for (; i < n; i++) {
        if (s[i] < '0' || s[i] > '9') return 0;
        v = v * 10 + (s[i] - '0');
    }
    *out = neg ? -v : v;
    return 1;
}

/* Decimal numbers of at most 19 significant digits and a power of ten within 10^27:
   w * 10^q (or w / 10^-q) is one correctly rounded operation on exact operands in the
   x87's 64-bit significand, and its rounding to double is the correct one unless the
   extended result lies exactly halfway between two doubles (its low 11 bits are then
   0x400): only that case, and every other form, goes to strtod. glibc's strtod takes
   ~1000 instructions for each 17-digit number of a generated scene (the sphereflake:
   45 M for 30k numbers, most of its load). Returns 1 and the value, or 0: not handled. */
static int decimal_fast(const char *s, size_t n, double *out)
{
#if defined(__x86_64__) && LDBL_MANT_DIG == 64
    static const long double pow10[28] = {
        1e0L,  1e1L,  1e2L,  1e3L,  1e4L,  1e5L,  1e6L,  1e7L,  1e8L,  1e9L,
        1e10L, 1e11L, 1e12L, 1e13L, 1e14L, 1e15L, 1e16L, 1e17L, 1e18L, 1e19L,
        1e20L, 1e21L, 1e22L, 1e23L, 1e24L, 1e25L, 1e26L, 1e27L};
    size_t i = 0;
    int neg = 0;
    if (i < n && s[i] == '-') neg = 1, i++;
    uint64_t w = 0;
    int digits = 0, seen = 0; /* significant digits in w; digits of the mantissa seen */
    long q = 0;
    for (; i < n && s[i] >= '0' && s[i] <= '9'; i++, seen++) {
        if (w == 0 && s[i] == '0') continue; /* leading zeros: not significant */
        if (++digits > 19) return 0;
        w = w * 10 + (uint64_t)(s[i] - '0');
    }
    if (i < n && s[i] == '.') {
        for (i++; i < n && s[i] >= '0' && s[i] <= '9'; i++, seen++) {
            q--;
            if (w == 0 && s[i] == '0') continue;
            if (++digits > 19) return 0;
            w = w * 10 + (uint64_t)(s[i] - '0');
        }
    }
    if (!seen) return 0;
    if (i < n && (s[i] == 'e' || s[i] == 'E')) {
        int eneg = 0, edigits = 0;
        long e = 0;
        if (++i < n && (s[i] == '-' || s[i] == '+')) eneg = s[i++] == '-';
        for (; i < n && s[i] >= '0' && s[i] <= '9'; i++) {
            if (++edigits > 4) return 0;
            e = e * 10 + (s[i] - '0');
        }
        if (!edigits) return 0;
        q += eneg ? -e : e;
    }
    if (i != n) return 0;
    if (w == 0) {
        *out = neg ? -0.0 : 0.0;
        return 1;
    }
    if (q < -27 || q > 27) return 0;
    long double r = q >= 0 ? (long double)w * pow10[q] : (long double)w / pow10[-q];
    uint64_t sig;
    memcpy(&sig, &r, sizeof sig); /* the x87 format's explicit 64-bit significand */
    if ((sig & 0x7ff) == 0x400) return 0;
    double d = (double)r;
    *out = neg ? -d : d;
    return 1;
#else
    (void)s, (void)n, (void)out;
    return 0;
#endif
}

int vw__parse_double(const char *s, size_t n, double *out)
{
    char buf[128];
    if (n == 0 || n >= sizeof buf) return 0;
    if (decimal_fast(s, n, out)) return 1;
    if (memchr(s, '\0', n)) return 0;
    memcpy(buf, s, n);
    buf[n] = '\0';
    char *endp;
    /* Decimal notation only: strtod read "0x10" in a scene as 16. */
    double v = vw_strtod_decimal(buf, &endp, 1);
    if (endp == buf) {
        /* "inf", "nan": no numbers here either, but named as what they are */
        const char *w = buf + (*buf == '+' || *buf == '-');
        if ((*w | 32) != 'i' && (*w | 32) != 'n') return 0;
        v = strtod(buf, &endp);
        return endp == buf + n ? -1 : 0;
    }
    if (endp != buf + n) return 0;
    if (!isfinite(v)) return -1;
    *out = v;
    return 1;
}

vw_status vw__input_error(char *err, size_t errlen, const char *name, int line,
                          const char *fmt, va_list ap)
{
    if (err && errlen) {
        int k = snprintf(err, errlen, "%s:%d: ", name, line);
        if (k >= 0 && (size_t)k < errlen) vsnprintf(err + k, errlen - (size_t)k, fmt, ap);
    }
    return VW_E_INPUT;
}

/* The warning handler: process-wide, like the readers it serves, and set before them. */
static vw_warning_fn warning_fn;
static void *warning_user;

VW_API void vw_scene_set_warning_handler(vw_warning_fn fn, void *user)
{
    warning_fn = fn;
    warning_user = fn ? user : NULL;
}

void vw__scene_warning(const char *name, int line, const char *fmt, va_list ap)
{
    char msg[1024];
    int k = snprintf(msg, sizeof msg, "%s:%d: warning: ", name, line);
    if (k >= 0 && (size_t)k < sizeof msg) vsnprintf(msg + k, sizeof msg - (size_t)k, fmt, ap);
    if (warning_fn)
        warning_fn(msg, warning_user);
    else
        fprintf(stderr, "%s\n", msg);
}

/* ---- builder ---------------------------------------------------------------- */

/* Grows *p to hold at least need elements. Capacities double, so n appends cost
   O(n) copies in all; the multiplication is checked so a huge count fails cleanly. */
static int grow(void **p, size_t *cap, size_t need, size_t elem)
{
    if (need <= *cap)
        return 1;
    size_t ncap = *cap ? *cap : 8;
    while (ncap < need) {
        if (ncap > SIZE_MAX / 2)
            return 0;
        ncap *= 2;
    }
    if (ncap > SIZE_MAX / elem)
        return 0;
    void *q = realloc(*p, ncap * elem);
    if (!q)
        return 0;
    *p = q;
    *cap = ncap;
    return 1;
}

vw_status vw__sb_init(vw__sb *b)
{
    memset(b, 0, sizeof *b);
    b->s = calloc(1, sizeof *b->s);
    return b->s ? VW_OK : VW_E_NOMEM;
}

vw_scene *vw__sb_finish(vw__sb *b)
{
    vw_scene *s = b->s;
    free(b->mat_hash);
    memset(b, 0, sizeof *b);
    return s;
}

void vw__sb_abort(vw__sb *b)
{
    vw_scene_free(vw__sb_finish(b));
}

vw_status vw__sb_close(vw__sb *b, vw_status st, vw_scene **out)
{
    if (st == VW_OK)
        *out = vw__sb_finish(b);
    else
        vw__sb_abort(b);
    return st;
}

void vw__default_material(vw_material *m)
{
    memset(m, 0, sizeof *m);
    m->diffuse[0] = m->diffuse[1] = m->diffuse[2] = 1.0f;
    m->ior = 1.0f;
}

vw_status vw__sb_add_light(vw__sb *b, const double pos[3], const float color[3])
{
    vw_scene *s = b->s;
    if (!grow((void **)&s->lights, &b->cap_lights, s->nlights + 1, sizeof *s->lights))
        return VW_E_NOMEM;
    vw_light *l = &s->lights[s->nlights++];
    memcpy(l->pos, pos, sizeof l->pos);
    memcpy(l->color, color, sizeof l->color);
    return VW_OK;
}

vw_status vw__sb_add_material(vw__sb *b, const vw_material *m, int *index)
{
    vw_scene *s = b->s;
    if (s->nmaterials >= INT32_MAX)
        return VW_E_LIMIT;
    if (!grow((void **)&s->materials, &b->cap_materials, s->nmaterials + 1,
              sizeof *s->materials))
        return VW_E_NOMEM;
    s->materials[s->nmaterials] = *m;
    *index = (int)s->nmaterials++;
    return VW_OK;
}

/* A material's values are all floats, so there is no padding and bit-identical values
   hash alike; where it was defined is not hashed. A value added after `line` would be
   left out of the hash, the comparison and the fingerprint: this says so at build time. */
_Static_assert(VW__MATERIAL_VALUE_BYTES == 15 * sizeof(float),
               "vw_material: its values are the floats before 'line'");
static uint64_t material_hash(const vw_material *m)
{
    return vw__fnv1a(VW__FNV_OFFSET, m, VW__MATERIAL_VALUE_BYTES);
}

static int mat_hash_insert(int *tab, size_t cap, const vw_material *mats, int index)
{
    size_t i = (size_t)material_hash(&mats[index]) & (cap - 1);
    while (tab[i] >= 0)
        i = (i + 1) & (cap - 1);
    tab[i] = index;
    return 1;
}

vw_status vw__sb_intern_material(vw__sb *b, const vw_material *m, int *index)
{
    vw_scene *s = b->s;
    /* Keep the load factor at or below 1/2 so probes stay short. */
    if ((s->nmaterials + 1) * 2 > b->mat_hash_cap) {
        size_t ncap = b->mat_hash_cap ? b->mat_hash_cap * 2 : 64;
        if (ncap > SIZE_MAX / sizeof(int))
            return VW_E_NOMEM;
        int *tab = malloc(ncap * sizeof *tab);
        if (!tab)
            return VW_E_NOMEM;
        for (size_t i = 0; i < ncap; i++)
            tab[i] = -1;
        for (size_t k = 0; k < s->nmaterials; k++)
            mat_hash_insert(tab, ncap, s->materials, (int)k);
        free(b->mat_hash);
        b->mat_hash = tab;
        b->mat_hash_cap = ncap;
    }
    size_t i = (size_t)material_hash(m) & (b->mat_hash_cap - 1);
    while (b->mat_hash[i] >= 0) {
        if (memcmp(&s->materials[b->mat_hash[i]], m, VW__MATERIAL_VALUE_BYTES) == 0) {
            *index = b->mat_hash[i];
            return VW_OK;
        }
        i = (i + 1) & (b->mat_hash_cap - 1);
    }
    vw_status st = vw__sb_add_material(b, m, index);
    if (st != VW_OK)
        return st;
    b->mat_hash[i] = *index;
    return VW_OK;
}

vw_status vw__sb_add_string(vw__sb *b, const char *str, size_t n, int *k)
{
    vw_scene *s = b->s;
    if (s->nstrings >= INT32_MAX || n == SIZE_MAX)
        return VW_E_LIMIT;
    if (!grow((void **)&s->strings, &b->cap_strings, s->nstrings + 1, sizeof *s->strings))
        return VW_E_NOMEM;
    char *copy = malloc(n + 1);
    if (!copy)
        return VW_E_NOMEM;
    memcpy(copy, str, n);
    copy[n] = '\0';
    s->strings[s->nstrings++] = copy;
    *k = (int)s->nstrings;
    return VW_OK;
}

static vw_status take_id(vw__sb *b, int *id)
{
    if (b->next_id == INT32_MAX)
        return VW_E_LIMIT;
    *id = b->next_id++;
    return VW_OK;
}

vw_status vw__sb_add_sphere(vw__sb *b, int material, const double c[3], double r)
{
    vw_scene *s = b->s;
    if (!grow((void **)&s->spheres, &b->cap_spheres, s->nspheres + 1, sizeof *s->spheres))
        return VW_E_NOMEM;
    vw_sphere *sp = &s->spheres[s->nspheres];
    vw_status st = take_id(b, &sp->id);
    if (st != VW_OK)
        return st;
    sp->material = material;
    sp->line = b->line;
    memcpy(sp->center, c, sizeof sp->center);
    sp->radius = r;
    s->nspheres++;
    return VW_OK;
}

vw_status vw__sb_add_cone(vw__sb *b, int material, const double base[3], double base_r,
                          const double apex[3], double apex_r)
{
    vw_scene *s = b->s;
    if (!grow((void **)&s->cones, &b->cap_cones, s->ncones + 1, sizeof *s->cones))
        return VW_E_NOMEM;
    vw_cone *c = &s->cones[s->ncones];
    vw_status st = take_id(b, &c->id);
    if (st != VW_OK)
        return st;
    c->material = material;
    c->line = b->line;
    memcpy(c->base, base, sizeof c->base);
    c->base_radius = base_r;
    memcpy(c->apex, apex, sizeof c->apex);
    c->apex_radius = apex_r;
    s->ncones++;
    return VW_OK;
}

vw_status vw__sb_add_vertex(vw__sb *b, const double v[3], int *index)
{
    vw_scene *s = b->s;
    if (s->nvertices >= INT32_MAX)
        return VW_E_LIMIT;
    if (!grow((void **)&s->vertices, &b->cap_vertices, s->nvertices + 1,
              sizeof *s->vertices))
        return VW_E_NOMEM;
    memcpy(s->vertices[s->nvertices], v, sizeof s->vertices[0]);
    *index = (int)s->nvertices++;
    return VW_OK;
}

void vw__sb_polygon_begin(vw__sb *b)
{
    b->poly_first = b->s->nindices;
}

vw_status vw__sb_polygon_corner(vw__sb *b, int vertex, const double *normal)
{
    vw_scene *s = b->s;
    if (s->nindices >= INT32_MAX)
        return VW_E_LIMIT;
    size_t oldcap = b->cap_indices;
    if (!grow((void **)&s->indices, &b->cap_indices, s->nindices + 1, sizeof *s->indices))
        return VW_E_NOMEM;
    if (s->normals && b->cap_indices != oldcap) {
        /* normals shadows indices; grow it in step and zero the new corners. */
        void *q = realloc(s->normals, b->cap_indices * sizeof *s->normals);
        if (!q) {
            b->cap_indices = oldcap;
            return VW_E_NOMEM;
        }
        s->normals = q;
        memset(s->normals + oldcap, 0, (b->cap_indices - oldcap) * sizeof *s->normals);
    }
    if (normal && !s->normals) {
        s->normals = calloc(b->cap_indices, sizeof *s->normals);
        if (!s->normals)
            return VW_E_NOMEM;
    }
    s->indices[s->nindices] = vertex;
    if (s->normals) {
        if (normal)
            memcpy(s->normals[s->nindices], normal, sizeof s->normals[0]);
        else
            memset(s->normals[s->nindices], 0, sizeof s->normals[0]);
    }
    s->nindices++;
    return VW_OK;
}

vw_status vw__sb_polygon_end(vw__sb *b, int material, int has_normals)
{
    vw_scene *s = b->s;
    size_t count = s->nindices - b->poly_first;
    if (count < 3 || count > INT32_MAX)
        return VW_E_INVAL;
    if (!grow((void **)&s->polygons, &b->cap_polygons, s->npolygons + 1,
              sizeof *s->polygons))
        return VW_E_NOMEM;
    vw_polygon *p = &s->polygons[s->npolygons];
    vw_status st = take_id(b, &p->id);
    if (st != VW_OK)
        return st;
    p->material = material;
    p->line = b->line;
    p->first = (int)b->poly_first;
    p->count = (int)count;
    p->has_normals = has_normals && s->normals ? 1 : 0;
    s->npolygons++;
    return VW_OK;
}

vw_status vw__sb_add_polygon(vw__sb *b, int material, int n, const double (*v)[3])
{
    vw__sb_polygon_begin(b);
    for (int i = 0; i < n; i++) {
        int vi;
        vw_status st = vw__sb_add_vertex(b, v[i], &vi);
        if (st == VW_OK)
            st = vw__sb_polygon_corner(b, vi, NULL);
        if (st != VW_OK)
            return st;
    }
    return vw__sb_polygon_end(b, material, 0);
}

/* ---- public: lifetime and reading -------------------------------------------- */

VW_API void vw_scene_free(vw_scene *s)
{
    if (!s)
        return;
    free(s->lights);
    free(s->materials);
    free(s->spheres);
    free(s->cones);
    free(s->polygons);
    free(s->vertices);
    free(s->indices);
    free(s->normals);
    for (size_t i = 0; i < s->nstrings; i++)
        free(s->strings[i]);
    free(s->strings);
    free(s);
}

static int has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), m = strlen(suffix);
    if (n < m)
        return 0;
    for (size_t i = 0; i < m; i++) {
        char c = s[n - m + i];
        if (c >= 'A' && c <= 'Z')
            c = (char)(c - 'A' + 'a');
        if (c != suffix[i])
            return 0;
    }
    return 1;
}

VW_API vw_status vw_scene_read_file(const char *path, vw_scene **out, char *err,
                                    size_t errlen)
{
    if (out)
        *out = NULL;
    if (!path || !out) {
        vw__errf(err, errlen, "vw_scene_read_file: NULL argument");
        return VW_E_INVAL;
    }
    int is_nff = has_suffix(path, ".nff"), is_obj = has_suffix(path, ".obj");
    int is_ply = has_suffix(path, ".ply");
    if (!is_nff && !is_obj && !is_ply) {
        vw__errf(err, errlen, "%s: unknown scene format (expected .nff, .obj or .ply)", path);
        return VW_E_INPUT;
    }
    char *text;
    size_t len;
    vw_status st = vw__read_whole_file(path, &text, &len, err, errlen);
    if (st != VW_OK)
        return st;
    if (is_nff) {
        st = vw_scene_read_nff(path, text, len, out, err, errlen);
    } else if (is_ply) {
        st = vw_scene_read_ply(path, text, len, out, err, errlen);
    } else {
        /* mtllib names are relative to the directory of the OBJ file. */
        const char *slash = strrchr(path, '/');
        char *dir;
        if (slash) {
            size_t n = (size_t)(slash - path);
            dir = malloc(n + 2);
            if (dir) {
                memcpy(dir, path, n);
                dir[n] = '\0';
                if (n == 0)
                    strcpy(dir, "/");
            }
        } else {
            dir = malloc(2);
            if (dir)
                strcpy(dir, ".");
        }
        if (!dir) {
            free(text);
            vw__errf(err, errlen, "%s: out of memory", path);
            return VW_E_NOMEM;
        }
        st = vw_scene_read_obj(path, text, len, dir, out, err, errlen);
        free(dir);
    }
    free(text);
    return st;
}

/* ---- public: queries ---------------------------------------------------------- */

VW_API size_t vw_scene_count_objects(const vw_scene *s)
{
    return s ? s->nspheres + s->ncones + s->npolygons : 0;
}

VW_API const char *vw_scene_string(const vw_scene *s, int k)
{
    return s && s->strings && k > 0 && (size_t)k <= s->nstrings ? s->strings[k - 1] : NULL;
}

VW_API const char *vw_text_shown(const char *s, size_t n, size_t max, char *out, size_t outlen)
{
    if (!out || !outlen) return out;
    size_t room = outlen - 1, cut = max && max < n ? max : n, i;
    if (cut > room) cut = room >= 3 ? room - 3 : room;
    for (i = 0; i < cut; i++) {
        unsigned char c = (unsigned char)s[i];
        out[i] = c >= 0x20 && c < 0x7f && c != '\'' ? (char)c : '?';
    }
    if (i < n && i + 3 <= room) {
        memcpy(out + i, "...", 3);
        i += 3;
    }
    out[i] = '\0';
    return out;
}

VW_API uint64_t vw_scene_fingerprint(const vw_scene *s)
{
    uint64_t h = VW__FNV_OFFSET;
    if (!s) return h;
#define H(x) (h = vw__fnv1a(h, &(x), sizeof(x)))
#define HN(p, n) (h = (p) && (n) ? vw__fnv1a(h, (p), sizeof *(p) * (n)) : h)
    H(s->background);
    H(s->nlights);
    for (size_t i = 0; i < s->nlights; i++) H(s->lights[i].pos), H(s->lights[i].color);
    H(s->nmaterials);
    /* Each material's values (all floats: no padding), not where it was defined: the
       same hash as the whole array gave when a material held nothing else. */
    for (size_t i = 0; i < s->nmaterials; i++)
        h = vw__fnv1a(h, &s->materials[i], VW__MATERIAL_VALUE_BYTES);
    H(s->nspheres);
    for (size_t i = 0; i < s->nspheres; i++) {
        const vw_sphere *x = &s->spheres[i];
        H(x->id), H(x->material), H(x->center), H(x->radius);
    }
    H(s->ncones);
    for (size_t i = 0; i < s->ncones; i++) {
        const vw_cone *x = &s->cones[i];
        H(x->id), H(x->material), H(x->base), H(x->base_radius), H(x->apex), H(x->apex_radius);
    }
    H(s->npolygons);
    for (size_t i = 0; i < s->npolygons; i++) {
        const vw_polygon *x = &s->polygons[i];
        H(x->id), H(x->material), H(x->first), H(x->count), H(x->has_normals);
    }
    H(s->nvertices);
    HN(s->vertices, s->nvertices);
    H(s->nindices);
    HN(s->indices, s->nindices);
    HN(s->normals, s->nindices);
#undef H
#undef HN
    return h;
}

static void box_empty(double lo[3], double hi[3])
{
    for (int k = 0; k < 3; k++) {
        lo[k] = INFINITY;
        hi[k] = -INFINITY;
    }
}

static void box_add(double lo[3], double hi[3], const double c[3], double r)
{
    for (int k = 0; k < 3; k++) {
        if (c[k] - r < lo[k])
            lo[k] = c[k] - r;
        if (c[k] + r > hi[k])
            hi[k] = c[k] + r;
    }
}

static void object_box(const vw_scene *s, vw_prim_kind kind, size_t i, double lo[3],
                       double hi[3])
{
    switch (kind) {
    case VW_PRIM_SPHERE:
        box_add(lo, hi, s->spheres[i].center, fabs(s->spheres[i].radius));
        break;
    case VW_PRIM_CONE:
        /* A disc of radius r lies inside the cube of half-size r around its centre;
           the cone is the convex hull of its two end discs. */
        box_add(lo, hi, s->cones[i].base, fabs(s->cones[i].base_radius));
        box_add(lo, hi, s->cones[i].apex, fabs(s->cones[i].apex_radius));
        break;
    case VW_PRIM_POLYGON: {
        const vw_polygon *p = &s->polygons[i];
        for (int k = 0; k < p->count; k++) {
            size_t at = (size_t)p->first + (size_t)k;
            if (at >= s->nindices)
                break;
            int vi = s->indices[at];
            if (vi >= 0 && (size_t)vi < s->nvertices)
                box_add(lo, hi, s->vertices[vi], 0.0);
        }
        break;
    }
    }
}

static void box_finish(double lo[3], double hi[3])
{
    if (lo[0] > hi[0] || lo[1] > hi[1] || lo[2] > hi[2])
        for (int k = 0; k < 3; k++)
            lo[k] = hi[k] = 0.0;
}

VW_API void vw_scene_bounds(const vw_scene *s, double lo[3], double hi[3])
{
    box_empty(lo, hi);
    if (s) {
        for (size_t i = 0; i < s->nspheres; i++)
            object_box(s, VW_PRIM_SPHERE, i, lo, hi);
        for (size_t i = 0; i < s->ncones; i++)
            object_box(s, VW_PRIM_CONE, i, lo, hi);
        for (size_t i = 0; i < s->npolygons; i++)
            object_box(s, VW_PRIM_POLYGON, i, lo, hi);
    }
    box_finish(lo, hi);
}

VW_API void vw_scene_object_bounds(const vw_scene *s, vw_prim_kind kind, size_t index,
                                   double lo[3], double hi[3])
{
    box_empty(lo, hi);
    if (s) {
        size_t n = kind == VW_PRIM_SPHERE ? s->nspheres
                 : kind == VW_PRIM_CONE   ? s->ncones
                 : kind == VW_PRIM_POLYGON ? s->npolygons : 0;
        if (index < n)
            object_box(s, kind, index, lo, hi);
    }
    box_finish(lo, hi);
}

/* Each kind's array is sorted by id (ids are handed out in file order), so a
   binary search per kind finds any id. */
#define FIND_IN(arr, n, id, out)                                                  \
    do {                                                                          \
        size_t lo_ = 0, hi_ = (n);                                                \
        while (lo_ < hi_) {                                                       \
            size_t mid_ = lo_ + (hi_ - lo_) / 2;                                  \
            if ((arr)[mid_].id < (id))                                            \
                lo_ = mid_ + 1;                                                   \
            else                                                                  \
                hi_ = mid_;                                                       \
        }                                                                         \
        (out) = (lo_ < (n) && (arr)[lo_].id == (id)) ? lo_ : SIZE_MAX;            \
    } while (0)

VW_API vw_status vw_scene_find_object(const vw_scene *s, int id, vw_prim_kind *kind,
                                      size_t *index)
{
    if (!s || !kind || !index)
        return VW_E_INVAL;
    size_t at;
    FIND_IN(s->spheres, s->nspheres, id, at);
    if (at != SIZE_MAX) {
        *kind = VW_PRIM_SPHERE;
        *index = at;
        return VW_OK;
    }
    FIND_IN(s->cones, s->ncones, id, at);
    if (at != SIZE_MAX) {
        *kind = VW_PRIM_CONE;
        *index = at;
        return VW_OK;
    }
    FIND_IN(s->polygons, s->npolygons, id, at);
    if (at != SIZE_MAX) {
        *kind = VW_PRIM_POLYGON;
        *index = at;
        return VW_OK;
    }
    return VW_E_INVAL;
}

/* A message that blames 'up' alone begins with 'up' (the NFF reader then names the
   up line). */
VW_API const char *vw_camera_problem(const vw_camera *cam)
{
    double d[3], c[3];
    for (int k = 0; k < 3; k++) {
        if (!isfinite(cam->from[k]) || !isfinite(cam->at[k]) || !isfinite(cam->up[k]))
            return "a coordinate of 'from', 'at' or 'up' is not a finite number";
        d[k] = cam->at[k] - cam->from[k];
    }
    if (d[0] == 0.0 && d[1] == 0.0 && d[2] == 0.0)
        return "'from' and 'at' are the same point";
    c[0] = d[1] * cam->up[2] - d[2] * cam->up[1];
    c[1] = d[2] * cam->up[0] - d[0] * cam->up[2];
    c[2] = d[0] * cam->up[1] - d[1] * cam->up[0];
    if (c[0] == 0.0 && c[1] == 0.0 && c[2] == 0.0)
        return "'up' is zero or parallel to the view direction";
    return NULL;
}

VW_API void vw_scene_default_camera(const vw_scene *s, vw_camera *cam)
{
    double lo[3], hi[3], c[3], e[3], emax = 0.0, cmax = 0.0;
    vw_scene_bounds(s, lo, hi);
    /* Halves first, so that neither the centre nor the extent overflows even for
       coordinates near DBL_MAX. */
    for (int k = 0; k < 3; k++) {
        c[k] = 0.5 * lo[k] + 0.5 * hi[k];
        e[k] = 0.5 * hi[k] - 0.5 * lo[k];
        if (e[k] > emax)
            emax = e[k];
        if (fabs(c[k]) > cmax)
            cmax = fabs(c[k]);
    }
    double d = 0.0;   /* the diagonal, scaled to avoid overflow in the squares */
    if (emax > 0.0) {
        for (int k = 0; k < 3; k++)
            d += (e[k] / emax) * (e[k] / emax);
        d = 2.0 * emax * sqrt(d);
    }
    /* A flat or point-like scene far from the origin still needs 'from' to differ
       from 'at' after rounding: never stand closer than 1e-6 of the distance to the
       origin. */
    if (d < 1e-6 * cmax)
        d = 1e-6 * cmax;
    if (!(d > 0.0) || !isfinite(d))
        d = 1.0;
    /* A bounding sphere of diameter d fits a 45 degree view from 1.31 d; 1.5 d
       leaves a margin. The direction is normalised (0.3, 0.4, 1). */
    static const double dir[3] = {0.27196414661021, 0.36261886214694, 0.90654715536736};
    int w = cam->width > 0 ? cam->width : 512, h = cam->height > 0 ? cam->height : 512;
    /* 'from' stays within a float's range, as the scene files' numbers must, so that the
       camera written as NFF reads back. For a scene at the edge of that range the view
       steps back on each axis toward the origin instead, and no farther than fits. */
    double t = 1.5 * d, side[3] = {1.0, 1.0, 1.0};
    int fits = 1;
    for (int k = 0; k < 3; k++)
        fits &= fabs(c[k] + t * dir[k]) <= FLT_MAX;
    if (!fits)
        for (int k = 0; k < 3; k++) {
            side[k] = c[k] > 0 ? -1.0 : 1.0;
            double room = 0.999 * (FLT_MAX + fabs(c[k])) / dir[k];
            if (t > room)
                t = room;
        }
    memset(cam, 0, sizeof *cam);
    for (int k = 0; k < 3; k++) {
        cam->at[k] = c[k];
        cam->from[k] = c[k] + side[k] * t * dir[k];
    }
    cam->up[1] = 1.0;
    cam->angle = 45.0;
    cam->hither = 1e-3 * (t < d ? t : d);
    cam->width = w;
    cam->height = h;
    cam->valid = 0;
}

/* ---- public: NFF writer ------------------------------------------------------- */

static void put3(FILE *f, const char *key, const double v[3])
{
    fprintf(f, "%s %.17g %.17g %.17g\n", key, v[0], v[1], v[2]);
}

/* Differ as bits: -0 and 0 compare equal, but a round trip must keep the sign. */
static int bits_differ(float a, float b) { return memcmp(&a, &b, sizeof a) != 0; }

static void write_material(FILE *f, const vw_material *m)
{
    /* diffuse is written with Kd = 1, so the reader's colour*Kd gives it back
       exactly; a float printed with 17 digits reads back to the same float. */
    fprintf(f, "f %.17g %.17g %.17g 1 %.17g %.17g %.17g %.17g\n", (double)m->diffuse[0],
            (double)m->diffuse[1], (double)m->diffuse[2], (double)m->specular[0],
            (double)m->shine, (double)m->transmit, (double)m->ior);
    if (bits_differ(m->specular[1], m->specular[0]) || bits_differ(m->specular[2], m->specular[0]))
        fprintf(f, "#vw Ks %.17g %.17g %.17g\n", (double)m->specular[0],
                (double)m->specular[1], (double)m->specular[2]);
    /* The reader sets the mirror weight to Ks (by the 'f' and by #vw Ks): only one that
       differs (an MTL illum without reflection) needs a line, after those. */
    if (bits_differ(m->reflect[0], m->specular[0]) || bits_differ(m->reflect[1], m->specular[1]) ||
        bits_differ(m->reflect[2], m->specular[2]))
        fprintf(f, "#vw Kr %.17g %.17g %.17g\n", (double)m->reflect[0],
                (double)m->reflect[1], (double)m->reflect[2]);
    if (bits_differ(m->emission[0], 0.0f) || bits_differ(m->emission[1], 0.0f) ||
        bits_differ(m->emission[2], 0.0f))
        fprintf(f, "#vw Ke %.17g %.17g %.17g\n", (double)m->emission[0],
                (double)m->emission[1], (double)m->emission[2]);
}

static const vw_material *material_of(const vw_scene *s, int index, vw_material *dflt)
{
    if (index >= 0 && (size_t)index < s->nmaterials)
        return &s->materials[index];
    vw__default_material(dflt);
    return dflt;
}

VW_API vw_status vw_scene_write_nff(const vw_scene *s, FILE *f)
{
    if (!s || !f)
        return VW_E_INVAL;
    vw_camera cam = s->camera;
    fprintf(f, "# vwalls %s scene: %zu objects\n", VW_VERSION_STRING,
            vw_scene_count_objects(s));
    if (!cam.valid) {
        vw_scene_default_camera(s, &cam);
        fprintf(f, "# the scene had no camera: a default view\n");
    }
    fprintf(f, "v\n");
    put3(f, "from", cam.from);
    put3(f, "at", cam.at);
    put3(f, "up", cam.up);
    fprintf(f, "angle %.17g\nhither %.17g\nresolution %d %d\n", cam.angle, cam.hither,
            cam.width, cam.height);
    fprintf(f, "b %.17g %.17g %.17g\n", (double)s->background[0],
            (double)s->background[1], (double)s->background[2]);
    for (size_t i = 0; i < s->nlights; i++) {
        const vw_light *l = &s->lights[i];
        fprintf(f, "l %.17g %.17g %.17g %.17g %.17g %.17g\n", l->pos[0], l->pos[1],
                l->pos[2], (double)l->color[0], (double)l->color[1], (double)l->color[2]);
    }
    /* Objects in id order: merge the three kinds, each sorted by id. A new 'f' is
       written whenever the material changes. */
    size_t is = 0, ic = 0, ip = 0;
    int cur = -2;
    vw_material dflt;
    for (;;) {
        int best = -1;
        long long bid = LLONG_MAX;
        if (is < s->nspheres && s->spheres[is].id < bid)
            best = 0, bid = s->spheres[is].id;
        if (ic < s->ncones && s->cones[ic].id < bid)
            best = 1, bid = s->cones[ic].id;
        if (ip < s->npolygons && s->polygons[ip].id < bid)
            best = 2, bid = s->polygons[ip].id;
        if (best < 0)
            break;
        int mat = best == 0 ? s->spheres[is].material
                : best == 1 ? s->cones[ic].material : s->polygons[ip].material;
        if (mat != cur) {
            write_material(f, material_of(s, mat, &dflt));
            cur = mat;
        }
        if (best == 0) {
            const vw_sphere *sp = &s->spheres[is++];
            fprintf(f, "s %.17g %.17g %.17g %.17g\n", sp->center[0], sp->center[1],
                    sp->center[2], sp->radius);
        } else if (best == 1) {
            const vw_cone *c = &s->cones[ic++];
            fprintf(f, "c\n%.17g %.17g %.17g %.17g\n%.17g %.17g %.17g %.17g\n", c->base[0],
                    c->base[1], c->base[2], c->base_radius, c->apex[0], c->apex[1],
                    c->apex[2], c->apex_radius);
        } else {
            const vw_polygon *p = &s->polygons[ip++];
            int nrm = p->has_normals && s->normals;
            fprintf(f, "%s %d\n", nrm ? "pp" : "p", p->count);
            for (int k = 0; k < p->count; k++) {
                size_t at = (size_t)p->first + (size_t)k;
                if (at >= s->nindices || s->indices[at] < 0 ||
                    (size_t)s->indices[at] >= s->nvertices)
                    return VW_E_INVAL;
                const double *v = s->vertices[s->indices[at]];
                fprintf(f, "%.17g %.17g %.17g", v[0], v[1], v[2]);
                if (nrm)
                    fprintf(f, " %.17g %.17g %.17g", s->normals[at][0], s->normals[at][1],
                            s->normals[at][2]);
                fputc('\n', f);
            }
        }
    }
    /* Flushed, so that a failure of the writes is known here: a small scene stayed in
       the stream's buffer and VW_OK came back for a stream that could not take it. */
    return fflush(f) != 0 || ferror(f) ? VW_E_IO : VW_OK;
}

VW_API vw_status vw_scene_write_nff_file(const vw_scene *s, const char *path, char *err,
                                         size_t errlen)
{
    if (!s || !path) {
        vw__errf(err, errlen, "vw_scene_write_nff_file: NULL argument");
        return VW_E_INVAL;
    }
    vw_outfile *of;
    vw_status st = vw_outfile_open(path, &of, err, errlen);
    if (st != VW_OK)
        return st;
    st = vw_scene_write_nff(s, vw_outfile_stream(of));
    /* A write error is the commit's to report, with its reason ("No space left on
       device"). */
    if (st != VW_OK && st != VW_E_IO) {
        vw_outfile_abort(of);
        vw__errf(err, errlen, "%s: scene is inconsistent", path);
        return st;
    }
    return vw_outfile_commit(of, err, errlen);
}
