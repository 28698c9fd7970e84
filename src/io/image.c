/* src/io/image.c - PNG (libpng) and PFM image writers, and a PNG reader for tests.
 *
 * Both writers go through vw_outfile (vwalls/outfile.h), so an image is either
 * complete under its name or absent. libpng reports errors by longjmp; the handlers here
 * record the message so it can be returned as "path: message".
 */
#include <errno.h>
#include <png.h>
#include <setjmp.h>
#include <stdlib.h>
#include <string.h>
#include <zlib.h>

#include "io/io_internal.h"
#include <strings.h>
#include "vwalls/image.h"
#include "vwalls/outfile.h"

/* Large enough for any real render, small enough that w*h*3 cannot overflow. */
#define MAX_SIDE (1 << 20)
#define MAX_PIXELS ((size_t)1 << 30)

typedef struct png_ctx {
    char msg[200];
} png_ctx;

static void on_png_error(png_structp png, png_const_charp msg)
{
    png_ctx *c = png_get_error_ptr(png);
    snprintf(c->msg, sizeof c->msg, "%s", msg);
    png_longjmp(png, 1);
}

static void on_png_warning(png_structp png, png_const_charp msg)
{
    (void)png;
    (void)msg;   /* warnings do not change the result */
}

static int check_size(const char *path, int w, int h, const void *pix, char *err,
                      size_t errlen)
{
    if (!path || !pix || w <= 0 || h <= 0 || w > MAX_SIDE || h > MAX_SIDE ||
        (size_t)w * (size_t)h > MAX_PIXELS) {
        vw__errf(err, errlen, "%s: bad image size %dx%d or no pixels", path ? path : "(null)",
                 w, h);
        return 0;
    }
    return 1;
}

/* ---- the compressed image data: blocks of rows on several threads ------------------ */

/* Rows per independently compressed block. Fixed, so the file's bytes do not depend on
   how many threads compress it; 64 rows of a 512-wide image are 96 KB, three times
   zlib's window, so starting each block afresh costs little (the 512x512 sphereflake:
   255,086 bytes against 254,725 in one stream). */
#define PNG_BLOCK_ROWS 64

/* One block: its rows Sub-filtered, as a raw deflate stream ending on a byte boundary
   (a sync flush; the last block finishes the stream), and their Adler-32. Blocks
   concatenated after a zlib header, with the combined Adler-32 after them, are the
   image's zlib stream (as pigz joins its blocks). */
typedef struct png_block {
    const uint8_t *rgb;
    int w, y0, y1, last;
    unsigned char *out; /* n bytes of deflate data, malloc'ed; NULL on failure */
    size_t n, raw;
    uLong adler;
} png_block;

static void deflate_block(png_block *b)
{
    size_t stride = 1 + (size_t)b->w * 3;
    b->raw = stride * (size_t)(b->y1 - b->y0);
    b->adler = adler32(0L, Z_NULL, 0);
    z_stream z;
    memset(&z, 0, sizeof z);
    /* zlib level 3 with the Sub filter on every row: a third of the instructions of
       the defaults (level 6, adaptive filter choice) for rendered images, at about the
       same size (sphereflake 512x512: 58 M against 169 M instructions, 255 KB against
       257 KB); the radiosity's smooth images need the filter (15 % larger without). */
    if (deflateInit2(&z, 3, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK) return;
    size_t cap = deflateBound(&z, (uLong)b->raw) + 64; /* + the sync flush's 5 bytes */
    unsigned char *row = malloc(stride), *out = malloc(cap);
    int ok = row && out;
    z.next_out = out;
    z.avail_out = (uInt)cap;
    for (int y = b->y0; ok && y < b->y1; y++) {
        const uint8_t *src = b->rgb + (size_t)y * (size_t)b->w * 3;
        row[0] = 1; /* Sub: each byte minus the byte of the pixel to its left */
        for (size_t i = 0; i < (size_t)b->w * 3; i++)
            row[1 + i] = (unsigned char)(src[i] - (i >= 3 ? src[i - 3] : 0));
        b->adler = adler32(b->adler, row, (uInt)stride);
        z.next_in = row;
        z.avail_in = (uInt)stride;
        ok = deflate(&z, Z_NO_FLUSH) == Z_OK && z.avail_in == 0;
    }
    if (ok) {
        int r = deflate(&z, b->last ? Z_FINISH : Z_SYNC_FLUSH);
        ok = (b->last ? r == Z_STREAM_END : r == Z_OK) && z.avail_out > 0;
    }
    deflateEnd(&z);
    free(row);
    if (ok) {
        b->n = cap - z.avail_out;
        unsigned char *fit = realloc(out, b->n ? b->n : 1); /* give back the bound's slack */
        b->out = fit ? fit : out;
    } else {
        free(out);
    }
}

typedef struct png_crew {
    png_block *blocks;
    int nblocks, nthreads; /* thread t compresses blocks t, t + nthreads, ... */
} png_crew;

static void deflate_blocks(int t, void *arg)
{
    png_crew *c = arg;
    for (int i = t; i < c->nblocks; i += c->nthreads) deflate_block(&c->blocks[i]);
}

/* The image's blocks (*out, nb of them), compressed on up to `threads` threads, and the
   Adler-32 of the whole stream; 0 when out of memory (nothing allocated then). */
static int compress_image(int w, int h, const uint8_t *rgb8, int threads, png_block **out,
                          int *nblocks, uLong *adler)
{
    int nb = (h + PNG_BLOCK_ROWS - 1) / PNG_BLOCK_ROWS;
    png_block *b = calloc((size_t)nb, sizeof *b);
    if (!b) return 0;
    for (int i = 0; i < nb; i++) {
        b[i].rgb = rgb8;
        b[i].w = w;
        b[i].y0 = i * PNG_BLOCK_ROWS;
        b[i].y1 = i + 1 < nb ? (i + 1) * PNG_BLOCK_ROWS : h;
        b[i].last = i + 1 == nb;
    }
    int nt = threads < 1 ? 1 : threads > 64 ? 64 : threads;
    png_crew crew = {b, nb, nt > nb ? nb : nt};
    vw_parallel(crew.nthreads, deflate_blocks, &crew);
    int ok = 1;
    *adler = adler32(0L, Z_NULL, 0);
    for (int i = 0; i < nb; i++) {
        ok &= b[i].out != NULL;
        *adler = adler32_combine(*adler, b[i].adler, (z_off_t)b[i].raw);
    }
    if (!ok) {
        for (int i = 0; i < nb; i++) free(b[i].out);
        free(b);
        return 0;
    }
    *out = b;
    *nblocks = nb;
    return 1;
}

/* The libpng part lives in its own function so that only its locals cross the
   setjmp; nothing here is modified after setjmp and read after longjmp. libpng frames
   the file (signature, IHDR, chunk lengths and CRCs); the image data is compressed
   beforehand (compress_image) and written as IDAT chunks, one per block. */
static int encode_png(FILE *f, int w, int h, const png_block *b, int nb, uLong adler,
                      png_ctx *ctx)
{
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, ctx, on_png_error,
                                              on_png_warning);
    if (!png) {
        snprintf(ctx->msg, sizeof ctx->msg, "out of memory");
        return 0;
    }
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, NULL);
        snprintf(ctx->msg, sizeof ctx->msg, "out of memory");
        return 0;
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return 0;
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGB,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    /* One IDAT chunk per block (a block is at most 64 rows: far below a chunk's 2^31
       bytes); the zlib header opens the first, the Adler-32 closes the last. */
    static const unsigned char header[2] = {0x78, 0x5e}; /* deflate, 32 KB window */
    unsigned char trailer[4];
    for (int k = 0; k < 4; k++) trailer[k] = (unsigned char)(adler >> (24 - 8 * k));
    for (int i = 0; i < nb; i++) {
        size_t len = b[i].n + (i == 0 ? 2 : 0) + (i + 1 == nb ? 4 : 0);
        png_write_chunk_start(png, (png_const_bytep) "IDAT", (png_uint_32)len);
        if (i == 0) png_write_chunk_data(png, header, 2);
        png_write_chunk_data(png, b[i].out, b[i].n);
        if (i + 1 == nb) png_write_chunk_data(png, trailer, 4);
        png_write_chunk_end(png);
    }
    png_write_chunk(png, (png_const_bytep) "IEND", NULL, 0);
    png_destroy_write_struct(&png, &info);
    return 1;
}

VW_API vw_status vw_image_write_png_threads(const char *path, int w, int h, const uint8_t *rgb8,
                                            int threads, char *err, size_t errlen)
{
    if (!check_size(path, w, h, rgb8, err, errlen))
        return VW_E_INVAL;
    png_block *b = NULL;
    int nb = 0;
    uLong adler = 0;
    if (!compress_image(w, h, rgb8, threads, &b, &nb, &adler)) {
        vw__errf(err, errlen, "%s: out of memory compressing the image", path);
        return VW_E_NOMEM;
    }
    vw_outfile *of = NULL;
    vw_status st = vw_outfile_open(path, &of, err, errlen);
    png_ctx ctx = {""};
    int ok = st == VW_OK && encode_png(vw_outfile_stream(of), w, h, b, nb, adler, &ctx);
    for (int i = 0; i < nb; i++) free(b[i].out);
    free(b);
    if (st != VW_OK) return st;
    /* A failed write of the stream is the commit's to report, with its reason. */
    if (!ok && !ferror(vw_outfile_stream(of))) {
        vw_outfile_abort(of);
        vw__errf(err, errlen, "%s: PNG write failed: %s", path, ctx.msg);
        return VW_E_IO;
    }
    st = vw_outfile_commit(of, err, errlen);
    return st == VW_OK && !ok ? VW_E_IO : st;
}

VW_API vw_status vw_image_write_png(const char *path, int w, int h, const uint8_t *rgb8,
                                    char *err, size_t errlen)
{
    return vw_image_write_png_threads(path, w, h, rgb8, 1, err, errlen);
}

VW_API vw_status vw_image_write_pfm(const char *path, int w, int h, const float *rgb,
                                    char *err, size_t errlen)
{
    if (!check_size(path, w, h, rgb, err, errlen))
        return VW_E_INVAL;
    vw_outfile *of;
    vw_status st = vw_outfile_open(path, &of, err, errlen);
    if (st != VW_OK)
        return st;
    FILE *f = vw_outfile_stream(of);
    fprintf(f, "PF\n%d %d\n-1.0\n", w, h);
    size_t rowlen = (size_t)w * 3;
    unsigned char *row = malloc(rowlen * 4);
    if (!row) {
        vw_outfile_abort(of);
        vw__errf(err, errlen, "%s: out of memory", path);
        return VW_E_NOMEM;
    }
    /* Bytes are assembled explicitly so the file is little-endian on any host. */
    for (int y = h - 1; y >= 0; y--) {
        const float *src = rgb + (size_t)y * rowlen;
        for (size_t i = 0; i < rowlen; i++) {
            uint32_t u;
            memcpy(&u, &src[i], 4);
            row[4 * i + 0] = (unsigned char)(u & 0xff);
            row[4 * i + 1] = (unsigned char)((u >> 8) & 0xff);
            row[4 * i + 2] = (unsigned char)((u >> 16) & 0xff);
            row[4 * i + 3] = (unsigned char)(u >> 24);
        }
        if (fwrite(row, 4, rowlen, f) != rowlen)
            break;
    }
    free(row);
    return vw_outfile_commit(of, err, errlen);
}

static int decode_png(FILE *f, int *w, int *h, uint8_t **out, png_ctx *ctx)
{
    png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, ctx, on_png_error,
                                             on_png_warning);
    if (!png) {
        snprintf(ctx->msg, sizeof ctx->msg, "out of memory");
        return 0;
    }
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_read_struct(&png, NULL, NULL);
        snprintf(ctx->msg, sizeof ctx->msg, "out of memory");
        return 0;
    }
    /* Locals assigned after setjmp and read after longjmp must be volatile. */
    uint8_t *volatile pix = NULL;
    png_bytep *volatile rows = NULL;
    if (setjmp(png_jmpbuf(png))) {
        free(pix);
        free(rows);
        png_destroy_read_struct(&png, &info, NULL);
        return 0;
    }
    png_init_io(png, f);
    png_read_info(png, info);
    png_uint_32 pw = png_get_image_width(png, info), ph = png_get_image_height(png, info);
    if (pw == 0 || ph == 0 || pw > MAX_SIDE || ph > MAX_SIDE ||
        (size_t)pw * ph > MAX_PIXELS)
        png_error(png, "image too large");
    png_set_expand(png);         /* palette and low-bit grey to 8-bit, tRNS to alpha */
    png_set_strip_16(png);
    png_set_strip_alpha(png);
    png_set_gray_to_rgb(png);
    png_set_interlace_handling(png);
    png_read_update_info(png, info);
    if (png_get_rowbytes(png, info) != (size_t)pw * 3)
        png_error(png, "unexpected row layout");
    pix = malloc((size_t)pw * ph * 3);
    rows = malloc(ph * sizeof *rows);
    if (!pix || !rows)
        png_error(png, "out of memory");
    for (png_uint_32 y = 0; y < ph; y++)
        rows[y] = pix + (size_t)y * pw * 3;
    png_read_image(png, rows);
    png_read_end(png, NULL);
    free(rows);
    png_destroy_read_struct(&png, &info, NULL);
    *out = pix;
    *w = (int)pw;
    *h = (int)ph;
    return 1;
}

VW_API vw_status vw_image_read_png(const char *path, int *w, int *h, uint8_t **rgb8,
                                   char *err, size_t errlen)
{
    if (!path || !w || !h || !rgb8) {
        vw__errf(err, errlen, "vw_image_read_png: NULL argument");
        return VW_E_INVAL;
    }
    *rgb8 = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) {
        vw__errf(err, errlen, "%s: cannot open: %s", path, strerror(errno));
        return VW_E_INPUT;
    }
    png_ctx ctx = {""};
    int ok = decode_png(f, w, h, rgb8, &ctx);
    fclose(f);
    if (!ok) {
        vw__errf(err, errlen, "%s: not a readable PNG: %s", path, ctx.msg);
        return VW_E_INPUT;
    }
    return VW_OK;
}

VW_API void vw_image_free(void *pixels)
{
    free(pixels);
}

vw_image_format vw_image_format_of(const char *path)
{
    size_t n = path ? strlen(path) : 0;
    if (n > 4 && !strcasecmp(path + n - 4, ".png")) return VW_IMAGE_PNG;
    if (n > 4 && !strcasecmp(path + n - 4, ".pfm")) return VW_IMAGE_PFM;
    return VW_IMAGE_NONE;
}
