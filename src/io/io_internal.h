/* src/io/io_internal.h - helpers shared by the scene readers, writers and generators.
 *
 * Not installed. Everything here has a vw__ name and hidden visibility: the scene
 * builder that every reader and generator fills, error formatting and whole-file
 * reading. (Output files are written by vw_outfile, vwalls/outfile.h.)
 */
#ifndef VW_IO_INTERNAL_H
#define VW_IO_INTERNAL_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>
#include "vwalls/scene.h"

/* Writes a formatted message into err (NULL or errlen 0: nothing written). The
   message is truncated, never overflowed. */
void vw__errf(char *err, size_t errlen, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Writes "name:line: message" into err, the form of every bad-input message of the
   readers (NULL or errlen 0: nothing written; truncated, never overflowed). Returns
   VW_E_INPUT so a reader can `return vw__input_error(...)`. */
vw_status vw__input_error(char *err, size_t errlen, const char *name, int line,
                          const char *fmt, va_list ap);

/* Reports "name:line: warning: message" through the handler of
   vw_scene_set_warning_handler (by default one line on stderr). */
void vw__scene_warning(const char *name, int line, const char *fmt, va_list ap);

/* A whole token as a decimal integer with an optional sign, at most maxlen characters
   (so it cannot overflow). Returns 1 and stores it, or 0 when the token is not one. */
int vw__parse_int(const char *s, size_t n, size_t maxlen, long long *out);

/* A whole token (n bytes, not NUL-terminated) as a number, exactly as strtod reads it
   but in decimal notation only (vw_strtod_decimal, a leading '+' allowed): 1 and the
   value, 0 when it is not a number (a hexadecimal float, or longer than 127 bytes), -1
   when it is NaN or infinite ("nan", "inf", or a decimal beyond DBL_MAX). Short
   decimals take an exact fast path (scene.c). */
int vw__parse_double(const char *s, size_t n, double *out);

/* The scene builder owns a scene under construction plus the capacities of its
   arrays. Invariants: ids are handed out densely in the order primitives are added;
   when s->normals is non-NULL it has as many entries as s->indices (capacity too),
   and corners added without a normal hold (0,0,0). */
typedef struct vw__sb {
    vw_scene *s;
    size_t cap_lights, cap_materials, cap_spheres, cap_cones, cap_polygons;
    size_t cap_vertices, cap_indices, cap_strings;
    int next_id;
    int line;                /* the reader's: the line of the object being added */
    size_t poly_first;       /* first index of the polygon being built */
    int *mat_hash;           /* open addressing over material indices, -1 empty */
    size_t mat_hash_cap;
} vw__sb;

vw_status vw__sb_init(vw__sb *b);
/* Hands the scene over (the builder is empty afterwards). */
vw_scene *vw__sb_finish(vw__sb *b);
void vw__sb_abort(vw__sb *b);
/* A reader's end: with st == VW_OK the scene goes to *out, else it is freed. Returns st. */
vw_status vw__sb_close(vw__sb *b, vw_status st, vw_scene **out);

/* The bytes of a vw_material that are its values: all floats, no padding, so that
   equal materials compare and hash alike whatever their file, line and name. */
#define VW__MATERIAL_VALUE_BYTES offsetof(vw_material, line)

void vw__default_material(vw_material *m);
/* Copies str[0..n) into the scene's strings; *k gets its number (vw_scene_string). */
vw_status vw__sb_add_string(vw__sb *b, const char *str, size_t n, int *k);
vw_status vw__sb_add_light(vw__sb *b, const double pos[3], const float color[3]);
/* Appends a material unconditionally (OBJ: names matter, values may repeat). */
vw_status vw__sb_add_material(vw__sb *b, const vw_material *m, int *index);
/* Returns the index of a material with bit-identical values, adding it if there is
   none. NFF has no material names, so equal values are the same material (the first
   one added keeps its file and line); this is also what makes write-then-read
   reproduce the material table. */
vw_status vw__sb_intern_material(vw__sb *b, const vw_material *m, int *index);
vw_status vw__sb_add_sphere(vw__sb *b, int material, const double c[3], double r);
vw_status vw__sb_add_cone(vw__sb *b, int material, const double base[3], double base_r,
                          const double apex[3], double apex_r);
vw_status vw__sb_add_vertex(vw__sb *b, const double v[3], int *index);
/* A polygon is built as begin, one corner per vertex, end. normal may be NULL. */
void vw__sb_polygon_begin(vw__sb *b);
vw_status vw__sb_polygon_corner(vw__sb *b, int vertex, const double *normal);
vw_status vw__sb_polygon_end(vw__sb *b, int material, int has_normals);
/* Drops the polygon being built, its corners so far (a reader that skips a face). */
static inline void vw__sb_polygon_drop(vw__sb *b)
{
    b->s->nindices = b->poly_first;
}
/* Convenience: a polygon from its own fresh vertices (no normals). */
vw_status vw__sb_add_polygon(vw__sb *b, int material, int n, const double (*v)[3]);

/* Is the byte one a text file cannot hold? NUL and the control characters but the
   blanks (tab, VT, FF) and the line ends (LF, CR); DEL too. Bytes from 0x80 up are
   accepted unjudged: UTF-8 names and comments must read, and so must the Latin-1 or
   Windows code page text of older exporters, which is not valid UTF-8. The OBJ, MTL
   and NFF readers refuse such a byte as binary data, at its line. */
static inline int vw__is_binary(unsigned char c)
{
    return (c < 0x20 && c != '\t' && c != '\n' && c != '\v' && c != '\f' && c != '\r') ||
           c == 0x7f;
}

/* How a message names a byte vw__is_binary refuses: "a NUL byte" or "control character
   0x08" (buf: at least 24 bytes). */
static inline const char *vw__binary_name(unsigned char c, char *buf)
{
    if (!c) return "a NUL byte";
    snprintf(buf, 24, "control character 0x%02x", c);
    return buf;
}

/* A UTF-8 byte order mark (Windows editors write one) is not part of the first line:
   left there, it would make the first keyword unknown. The OBJ, MTL and NFF readers
   start after it. */
static inline size_t vw__bom_length(const char *text, size_t len)
{
    return len >= 3 && !memcmp(text, "\xEF\xBB\xBF", 3) ? 3 : 0;
}

/* A DOS end-of-file mark (Ctrl-Z, 0x1A) as the text's last byte is not part of it: DOS
   editors and tools of the SPD's time ended text files with one. The NFF, OBJ and MTL
   readers end their text before it (and the PLY reader's ASCII data); anywhere else it
   is a control character like any other. Returns the text's length without it. */
static inline size_t vw__text_length(const char *text, size_t len)
{
    return len && text[len - 1] == 0x1a ? len - 1 : len;
}

/* Reads a whole file into a NUL-terminated buffer (the NUL is not counted in *len). */
vw_status vw__read_whole_file(const char *path, char **text, size_t *len, char *err,
                              size_t errlen);

#endif
