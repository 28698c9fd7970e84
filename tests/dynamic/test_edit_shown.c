/* test_edit_shown.c - the edit-script parser's messages show the script's words as the
 * scene readers show a file's tokens (vw_text_shown): a script may be any file, and
 * `vwalls animate scene.nff garbage.bin` printed its raw bytes, escape sequences
 * included, to the terminal. Every message that quotes a word is checked: printable
 * ASCII only, the word's bad bytes and quotes as '?', bounded in length.
 * Usage: test_edit_shown
 */
#include <stdio.h>
#include <string.h>

#include "vw_test.h"
#include "vwalls/dynamic.h"

/* Is every byte of s printable ASCII? */
static int printable(const char *s)
{
    for (; *s; s++)
        if ((unsigned char)*s < 0x20 || (unsigned char)*s >= 0x7f)
            return 0;
    return 1;
}

int main(void)
{
    static const struct {
        const char *line, *want;
    } cases[] = {
        {"\x1b[2J\x7f\x01gone", "s:3: unknown command '?[2J??gone'"},
        {"mov\xc3\xa9 1 2 3 4", "s:3: unknown command 'mov?" "?'"},
        {"move \x1b[31m 1 2 3", "s:3: bad object id '?[31m'"},
        {"move 1 1\a 2 3", "s:3: bad number '1?' (expected 'move ID dx dy dz')"},
        {"rotate 1 0 0 1 9'0", "s:3: bad number '9?0' (expected 'rotate ID ax ay az DEGREES')"},
        {"add \x9b" "cube 0 0 0 1", "s:3: can only add a sphere, not '?cube'"},
        {"add sphere 0 \x1b 0 1", "s:3: bad number '?' (expected 'add sphere x y z r [MATERIAL]')"},
        {"add sphere 0 0 0 1 \x1b]0;owned\x07", "s:3: bad material index '?]0;owned?'"},
        /* Numbers in decimal notation only, as in scene files (strtod took "0x10"). */
        {"move 1 0x10 0 0", "s:3: bad number '0x10' (expected 'move ID dx dy dz')"},
        {"add sphere 0 0 0 -0X1p0", "s:3: bad number '-0X1p0' (expected 'add sphere x y z r [MATERIAL]')"},
        /* A long word is cut: a message stays one readable line. */
        {"xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx",
         "s:3: unknown command 'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx...'"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        vw_edit e;
        char err[512] = "";
        vw_status st = vw_edit_parse(cases[i].line, "s", 3, &e, err, sizeof err);
        EXPECT(st == VW_E_INPUT && printable(err) && !strcmp(err, cases[i].want),
               "case %zu: status %d, '%s', expected '%s'", i, (int)st, err, cases[i].want);
    }
    /* Words that are fine are still quoted as they are. */
    vw_edit e;
    char err[512];
    CHECK(vw_edit_parse("bogus 1", "s", 1, &e, err, sizeof err) == VW_E_INPUT);
    CHECK(!strcmp(err, "s:1: unknown command 'bogus'"));
    CHECK(vw_edit_parse("move 2 1 2 3", "s", 1, &e, err, sizeof err) == VW_OK);
    CHECK(vw_edit_parse("move 2 +1 -.5 2e-1", "s", 1, &e, err, sizeof err) == VW_OK);
    CHECK(e.v[0] == 1 && e.v[1] == -0.5 && e.v[2] == 0.2);
    TEST_DONE();
}
