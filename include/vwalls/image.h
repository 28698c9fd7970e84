/* vwalls/image.h - writing rendered images (PNG, PFM) and reading PNG back.
 *
 * Pixels are row-major, top row first, RGB interleaved. Writers are atomic: they
 * write "path.tmp.XXXXXX" in the same directory and rename it over path only when
 * everything was written, so a failure never leaves a partial file behind.
 */
#ifndef VWALLS_IMAGE_H
#define VWALLS_IMAGE_H

#include <stddef.h>
#include <stdint.h>
#include "vwalls/common.h"

#ifdef __cplusplus
extern "C" {
#endif

/* 8-bit RGB PNG. VW_E_INVAL for bad sizes, VW_E_IO when the file cannot be written;
   err gets "path: reason". */
VW_API vw_status vw_image_write_png(const char *path, int w, int h, const uint8_t *rgb8,
                                    char *err, size_t errlen);
/* The same, compressed on up to `threads` threads (blocks of 64 rows each; a serial
   phase of every render, so the command line passes its worker count). The file's
   bytes do not depend on the number of threads. */
VW_API vw_status vw_image_write_png_threads(const char *path, int w, int h, const uint8_t *rgb8,
                                            int threads, char *err, size_t errlen);
/* Portable float map: header "PF\n<w> <h>\n-1.0\n" (negative scale: little-endian),
   then rows bottom first, as the format prescribes. */
VW_API vw_status vw_image_write_pfm(const char *path, int w, int h, const float *rgb,
                                    char *err, size_t errlen);
/* Reads any PNG as 8-bit RGB (palette, grey and 16-bit are converted, alpha is
   dropped). *rgb8 is allocated; release it with vw_image_free. */
VW_API vw_status vw_image_read_png(const char *path, int *w, int *h, uint8_t **rgb8,
                                   char *err, size_t errlen);
VW_API void vw_image_free(void *pixels);

/* The format a file name asks for by its extension, case aside: the commands write a
   PNG for .png and a PFM for .pfm, and refuse other names before any work. */
typedef enum vw_image_format {
    VW_IMAGE_NONE = -1, /* neither */
    VW_IMAGE_PNG = 0,
    VW_IMAGE_PFM = 1
} vw_image_format;
VW_API vw_image_format vw_image_format_of(const char *path);

#ifdef __cplusplus
}
#endif
#endif
