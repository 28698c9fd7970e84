/* test_io_image.c - PNG write/read round trip, the PFM layout, and atomic writes: a
 * failed write (missing directory, unwritable directory, file size limit hit in the
 * middle) leaves neither a partial file nor a temporary, and an old file survives.
 */
#define _GNU_SOURCE
#include <dirent.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "io_test_util.h"
#include "vw_test.h"
#include "vwalls/image.h"

static int file_exists(const char *p)
{
    struct stat st;
    return stat(p, &st) == 0;
}

static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    struct dirent *e;
    while (d && (e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
            n++;
    if (d)
        closedir(d);
    return n;
}

static uint8_t *noise(int w, int h, uint64_t seed)
{
    uint8_t *p = malloc((size_t)w * h * 3);
    for (size_t i = 0; i < (size_t)w * h * 3; i++) {
        seed = seed * 6364136223846793005ull + 1442695040888963407ull;
        p[i] = (uint8_t)(seed >> 56);
    }
    return p;
}

int main(void)
{
    char dir[] = "/tmp/vw_io_image_XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[1024], err[512];

    /* PNG round trip, bit for bit. */
    int w = 37, h = 23;
    uint8_t *img = noise(w, h, 42);
    snprintf(path, sizeof path, "%s/a.png", dir);
    CHECK_EQ_INT(vw_image_write_png(path, w, h, img, err, sizeof err), VW_OK);
    int rw, rh;
    uint8_t *back;
    CHECK_EQ_INT(vw_image_read_png(path, &rw, &rh, &back, err, sizeof err), VW_OK);
    CHECK_EQ_INT(rw, w);
    CHECK_EQ_INT(rh, h);
    CHECK(memcmp(img, back, (size_t)w * h * 3) == 0);
    vw_image_free(back);
    CHECK_EQ_INT(count_entries(dir), 1);   /* no temporary left over */

    /* Compressed on several threads (blocks of 64 rows): read back bit for bit, and the
       same file bytes for every thread count, at heights around the block size. */
    {
        static const int hs[] = {1, 63, 64, 65, 130, 200}, ws[] = {1, 37, 300};
        for (size_t a = 0; a < sizeof hs / sizeof *hs; a++)
            for (size_t b = 0; b < sizeof ws / sizeof *ws; b++) {
                int W = ws[b], H = hs[a];
                uint8_t *im = noise(W, H, 7 + a * 3 + b);
                for (int y = 0; y < H / 2; y++) /* a smooth half too */
                    for (int x = 0; x < W * 3; x++) im[(size_t)y * W * 3 + x] = (uint8_t)(x + y);
                char p1[1100], p2[1100];
                snprintf(p1, sizeof p1, "%s/t1.png", dir);
                CHECK_EQ_INT(vw_image_write_png_threads(p1, W, H, im, 1, err, sizeof err), VW_OK);
                for (int t = 2; t <= 8; t *= 2) {
                    snprintf(p2, sizeof p2, "%s/t%d.png", dir, t);
                    CHECK_EQ_INT(vw_image_write_png_threads(p2, W, H, im, t, err, sizeof err), VW_OK);
                    FILE *f1 = fopen(p1, "rb"), *f2 = fopen(p2, "rb");
                    CHECK(f1 && f2);
                    int c1, c2, same = 1;
                    do {
                        c1 = fgetc(f1), c2 = fgetc(f2);
                        same &= c1 == c2;
                    } while (c1 != EOF && c2 != EOF);
                    fclose(f1), fclose(f2);
                    EXPECT(same, "%dx%d: the file on %d threads differs from one thread's", W, H, t);
                    uint8_t *rb;
                    int bw, bh;
                    CHECK_EQ_INT(vw_image_read_png(p2, &bw, &bh, &rb, err, sizeof err), VW_OK);
                    EXPECT(bw == W && bh == H && memcmp(im, rb, (size_t)W * H * 3) == 0,
                           "%dx%d on %d threads does not read back", W, H, t);
                    vw_image_free(rb);
                    remove(p2);
                }
                remove(p1);
                free(im);
            }
        CHECK_EQ_INT(vw_test_failures, 0);
    }
    /* Not a PNG: a clean error. */
    snprintf(path, sizeof path, "%s/not.png", dir);
    FILE *f = fopen(path, "w");
    fputs("hello", f);
    fclose(f);
    CHECK_EQ_INT(vw_image_read_png(path, &rw, &rh, &back, err, sizeof err), VW_E_INPUT);
    CHECK(back == NULL);
    unlink(path);

    /* PFM: header, little-endian, bottom row first. */
    float px[2][3][3];
    for (int y = 0; y < 2; y++)
        for (int x = 0; x < 3; x++)
            for (int c = 0; c < 3; c++)
                px[y][x][c] = (float)(y * 100 + x * 10 + c) + 0.5f;
    snprintf(path, sizeof path, "%s/a.pfm", dir);
    CHECK_EQ_INT(vw_image_write_pfm(path, 3, 2, &px[0][0][0], err, sizeof err), VW_OK);
    unsigned char buf[256];
    f = fopen(path, "rb");
    size_t n = fread(buf, 1, sizeof buf, f);
    fclose(f);
    const char *hdr = "PF\n3 2\n-1.0\n";
    size_t hl = strlen(hdr);
    CHECK_EQ_INT(n, hl + 2 * 3 * 3 * 4);
    CHECK(memcmp(buf, hdr, hl) == 0);
    for (int i = 0; i < 18; i++) {
        int y = 1 - i / 9, x = (i % 9) / 3, c = i % 3;   /* file row 0 = image row 1 */
        const unsigned char *b = buf + hl + 4 * i;
        uint32_t u = (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 |
                     (uint32_t)b[3] << 24;
        float v;
        memcpy(&v, &u, 4);
        CHECK(v == px[y][x][c]);
    }

    /* Bad arguments. */
    CHECK_EQ_INT(vw_image_write_png(path, 0, 5, img, err, sizeof err), VW_E_INVAL);

    /* Missing directory: an error, nothing created. */
    snprintf(path, sizeof path, "%s/missing/x.png", dir);
    CHECK_EQ_INT(vw_image_write_png(path, w, h, img, err, sizeof err), VW_E_IO);
    CHECK(strstr(err, path) == err);
    CHECK(!file_exists(path));

    /* A write that fails half-way (file size limit): the old file stays as it was and
       no temporary is left behind. */
    snprintf(path, sizeof path, "%s/big.png", dir);
    f = fopen(path, "w");
    fputs("old", f);
    fclose(f);
    int before = count_entries(dir);
    uint8_t *big = noise(256, 256, 7);   /* incompressible: ~200 kB of PNG */
    struct rlimit old;
    CHECK(file_size_limit(4096, &old) == 0);
    vw_status st = vw_image_write_png(path, 256, 256, big, err, sizeof err);
    float *fbig = calloc((size_t)256 * 256 * 3, sizeof *fbig);
    char err2[512];
    vw_status st2 = vw_image_write_pfm(path, 256, 256, fbig, err2, sizeof err2);
    free(fbig);
    CHECK(file_size_restore(&old) == 0);
    printf("size-limited write: %s\n", err);
    CHECK_EQ_INT(st, VW_E_IO);
    CHECK_EQ_INT(st2, VW_E_IO);
    CHECK_EQ_INT(count_entries(dir), before);
    f = fopen(path, "r");
    char got[8] = "";
    CHECK(fgets(got, sizeof got, f) != NULL);
    fclose(f);
    CHECK(strcmp(got, "old") == 0);
    free(big);

    /* An unwritable directory (meaningless for root, who may write anyway). */
    if (geteuid() != 0) {
        char ro[600];
        snprintf(ro, sizeof ro, "%s/ro", dir);
        CHECK(mkdir(ro, 0555) == 0);
        snprintf(path, sizeof path, "%s/x.png", ro);
        CHECK_EQ_INT(vw_image_write_png(path, w, h, img, err, sizeof err), VW_E_IO);
        CHECK(count_entries(ro) == 0);
        rmdir(ro);
    } else {
        printf("running as root: unwritable-directory case skipped\n");
    }

    /* Clean up. */
    DIR *d = opendir(dir);
    struct dirent *e;
    while ((e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            unlink(path);
        }
    closedir(d);
    rmdir(dir);
    free(img);
    TEST_DONE();
}
