/* test_io_nff_input.c - what the NFF reader takes as text, as the OBJ reader does: a NUL
 * byte or another control character (below 0x20 but tab, LF, VT, FF and CR; and DEL)
 * anywhere, a comment or a "#vw" line included, is refused at the byte's physical line
 * with the OBJ reader's words (a NUL in a comment used to pass unseen, one in a number
 * to read as a "bad number"); tab, VT, FF and every byte from 0x80 up (UTF-8, Latin-1)
 * stay accepted. An error earlier in the file is still the one reported. A UTF-8 byte
 * order mark before the first line is skipped; numbers are decimal (no "0x10"). A DOS
 * end-of-file mark (Ctrl-Z) as the last byte is not part of the text.
 * Usage: test_io_nff_input (no data: every input is made here)
 */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io_test_util.h"
#include "vw_test.h"

#define VIEW "v from 0 -5 0 at 0 0 0 up 0 0 1 angle 45 hither 0.1 resolution 8 8\n"
#define FILL "f 1 0 0 1 0 0 0 1\n"

/* The text (n bytes) is refused with exactly the message want; if convert is set, also
   with its LFs made CR or CRLF line ends (the same line named). */
static void refused_ends(const char *text, size_t n, const char *want, int convert)
{
    for (int ends = -1; ends < (convert ? 2 : 0); ends++) {
        size_t m = n;
        char *t = ends < 0 ? NULL : vw_test_line_ends(text, n, ends, &m), err[512] = "";
        vw_scene *s = (vw_scene *)1;
        vw_status st = vw_scene_read_nff("t.nff", t ? t : text, m, &s, err, sizeof err);
        EXPECT(st == VW_E_INPUT && s == NULL && !strcmp(err, want),
               "line ends %d: status %d, message '%s', expected '%s'", ends, (int)st, err, want);
        free(t);
    }
}

static void refused(const char *text, size_t n, const char *want)
{
    refused_ends(text, n, want, 1);
}

#define REFUSED(lit, want) refused(lit, sizeof lit - 1, want)

/* The text is read, with the given numbers of spheres and lights. */
static void accepted(const char *text, size_t n, size_t spheres, size_t lights)
{
    char err[512] = "";
    vw_scene *s = NULL;
    vw_status st = vw_scene_read_nff("t.nff", text, n, &s, err, sizeof err);
    EXPECT(st == VW_OK && s && s->nspheres == spheres && s->nlights == lights,
           "status %d (%s), %zu spheres (want %zu), %zu lights (want %zu)", (int)st, err,
           st == VW_OK ? s->nspheres : 0, spheres, st == VW_OK ? s->nlights : 0, lights);
    vw_scene_free(s);
}

#define ACCEPTED(lit, spheres, lights) accepted(lit, sizeof lit - 1, spheres, lights)

static void binary_bytes(void)
{
    /* In comments: a NUL, a backspace, DEL; on a comment line of its own, after an
       entity, in a "#vw" extension line and in the file's last line (no line end). */
    REFUSED(VIEW FILL "# made by \0 x\ns 0 0 0 1\n",
            "t.nff:3: a NUL byte: binary data, not NFF text");
    REFUSED(VIEW FILL "s 0 0 0 1 # a\bc\n",
            "t.nff:3: control character 0x08: binary data, not NFF text");
    REFUSED(VIEW FILL "#vw Ks 1 1 1 \x7f\ns 0 0 0 1\n",
            "t.nff:3: control character 0x7f: binary data, not NFF text");
    REFUSED(VIEW FILL "s 0 0 0 1\n# \x1b[0m",
            "t.nff:4: control character 0x1b: binary data, not NFF text");
    /* In a token, at its start, alone between blanks. */
    REFUSED(VIEW "s 0 0\0 0 1\n", "t.nff:2: a NUL byte: binary data, not NFF text");
    REFUSED(VIEW "s 0 0 0\n\x02" "1\n",
            "t.nff:3: control character 0x02: binary data, not NFF text");
    REFUSED(VIEW "s 0 0 0 1\n\n \x04 \n",
            "t.nff:4: control character 0x04: binary data, not NFF text");
    REFUSED("\x7f" "ELF\x02\x01\x01\0\0\0\n",
            "t.nff:1: control character 0x7f: binary data, not NFF text");
    /* Where the reader looks ahead: for a light's optional colour, and for another
       line of a 'v' block. */
    REFUSED(VIEW "l 0 0 5\n\x01\n", "t.nff:3: control character 0x01: binary data, not NFF text");
    REFUSED(VIEW "\x1f\x8b\x08", "t.nff:2: control character 0x1f: binary data, not NFF text");
    REFUSED("v from 0 -5 0 at 0 0 0\nup 0 0 1 \x0e angle 45\n",
            "t.nff:2: control character 0x0e: binary data, not NFF text");
    /* In a polygon's vertex list, lines after its keyword. */
    REFUSED(VIEW FILL "p 3\n0 0 0\n1 0 0\n0 1\x03 0\n",
            "t.nff:6: control character 0x03: binary data, not NFF text");
    /* Lines ended by a lone CR and by CRLF, then the byte: its line counted right. */
    static const char mixed[] = VIEW "# one\r# two\r\n# \0\n";
    refused_ends(mixed, sizeof mixed - 1, "t.nff:4: a NUL byte: binary data, not NFF text", 0);

    /* Every byte below 0x20 and DEL in a comment: refused unless a blank or a line end. */
    for (int c = 0; c < 0x80; c++) {
        char text[256], want[128];
        int n = snprintf(text, sizeof text, "%s%s# a%c\ns 0 0 0 1\n", VIEW, FILL, 'Z');
        char *z = memchr(text, 'Z', (size_t)n);
        *z = (char)c;
        int bin = (c < 0x20 && c != '\t' && c != '\n' && c != '\v' && c != '\f' && c != '\r') ||
                  c == 0x7f;
        if (!bin) {
            accepted(text, (size_t)n, 1, 0);
            continue;
        }
        if (c == 0)
            snprintf(want, sizeof want, "t.nff:3: a NUL byte: binary data, not NFF text");
        else
            snprintf(want, sizeof want,
                     "t.nff:3: control character 0x%02x: binary data, not NFF text", c);
        refused(text, (size_t)n, want);
    }

    /* The first problem in the file is the one reported, as in OBJ. */
    REFUSED(VIEW "s 0 0 0 0\n# \0\n", "t.nff:2: sphere radius must not be zero");
    REFUSED(VIEW "q\n# \0\n", "t.nff:2: unknown keyword 'q'");
}

static void text_bytes(void)
{
    /* Blanks that are not spaces, between tokens and in comments. */
    ACCEPTED(VIEW FILL "s\t0 0\v0\f1\n# tab\there, VT\v, FF\f\nl 0 0 5\t1 1 1\n", 1, 1);
    /* UTF-8 and Latin-1 comments (an accent, a degree sign, a byte order mark inside). */
    ACCEPTED(VIEW FILL "# caf\xc3\xa9 20\xc2\xb0 \xef\xbb\xbf\ns 0 0 0 1\n# caf\xe9\n", 1, 0);
    ACCEPTED(VIEW FILL "#vw Ks 0.5 0.5 0.5 # r\xc3\xa9glage\ns 0 0 0 1\n", 1, 0);
    /* Every byte from 0x80 up, in one comment. */
    char text[1024];
    size_t n = (size_t)snprintf(text, sizeof text, "%s%s# ", VIEW, FILL);
    for (int c = 0x80; c < 0x100; c++)
        text[n++] = (char)c;
    n += (size_t)snprintf(text + n, sizeof text - n, "\ns 0 0 0 1\n");
    accepted(text, n, 1, 0);
    /* Such a byte in a token is no binary data: the token is what is wrong (and is
       shown printable). */
    REFUSED(VIEW "s 0 0 0 1\xc3\xa9\n", "t.nff:2: bad number '1?" "?' in 's'");
    /* A UTF-8 byte order mark (Notepad's) is not part of the first keyword, as in OBJ
       (it was "unknown keyword '???v'"); anywhere else it is no blank. */
    ACCEPTED("\xef\xbb\xbf" VIEW FILL "s 0 0 0 1\n", 1, 0);
    ACCEPTED("\xef\xbb\xbf# comment\n" VIEW FILL "s 0 0 0 1\n", 1, 0);
    REFUSED("\xef\xbb\xbf" VIEW "\xef\xbb\xbfs 0 0 0 1\n", "t.nff:2: unknown keyword '???s'");
    /* Decimal notation only: strtod read "0x10" as 16; "nan" and "inf" keep their own
       message. */
    REFUSED(VIEW "s 0x10 0 0 1\n", "t.nff:2: bad number '0x10' in 's'");
    REFUSED(VIEW "s 0 0 0 -0X1p0\n", "t.nff:2: bad number '-0X1p0' in 's'");
    ACCEPTED(VIEW FILL "s +1 0 0 +.5e+0\n", 1, 0);
}

/* A DOS end-of-file mark (Ctrl-Z) as the file's last byte ends the text (it was refused
   as binary data); anywhere else it is a control character as before. */
static void dos_eof(void)
{
    ACCEPTED(VIEW FILL "s 0 0 0 1\r\n\x1a", 1, 0);
    ACCEPTED(VIEW FILL "s 0 0 0 1\x1a", 1, 0);
    ACCEPTED("\xEF\xBB\xBF" VIEW "\x1a", 0, 0);
    REFUSED(VIEW FILL "s 0 0 0 1\x1a\n", "t.nff:3: control character 0x1a: binary data, not NFF text");
    REFUSED(VIEW FILL "s 0 0 0 1\n\x1a\x1a", "t.nff:4: control character 0x1a: binary data, not NFF text");
    REFUSED(VIEW FILL "s 0 0 0\n\x1a", "t.nff:3: file ends in the middle of 's'");
}

int main(void)
{
    binary_bytes();
    text_bytes();
    dos_eof();
    TEST_DONE();
}
