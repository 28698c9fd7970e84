/* edit.c - the edit language of the dynamic-scene handler (docs/edit-language.md):
 * one command per line, '#' starts a comment, words separated by blanks. This file
 * only parses; whether an id exists is decided when the edit is applied.
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "vwalls/dynamic.h"

#define MAX_WORDS 8

static vw_status fail(char *err, size_t errlen, const char *name, int line, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));
static vw_status fail(char *err, size_t errlen, const char *name, int line, const char *fmt, ...)
{
    if (err && errlen) {
        int n = snprintf(err, errlen, "%s:%d: ", name ? name : "edits", line);
        if (n < 0) n = 0;
        if ((size_t)n < errlen) {
            va_list ap;
            va_start(ap, fmt);
            vsnprintf(err + n, errlen - (size_t)n, fmt, ap);
            va_end(ap);
        }
    }
    return VW_E_INPUT;
}

/* A word of the script shown in a message: the script may be any file (binary data,
   escape sequences), and the terminal must get printable text, as from the scene
   readers. */
#define SHOWN_BUF (VW_SHOWN_NAME + 8)
static const char *shown(const char *w, char buf[SHOWN_BUF])
{
    return vw_text_shown(w, strlen(w), VW_SHOWN_NAME, buf, SHOWN_BUF);
}

/* A finite number, the whole word. */
static int number(const char *w, double *out)
{
    char *end;
    double v = vw_strtod_decimal(w, &end, 1); /* decimal notation, as in scene files */
    if (end == w || *end || !isfinite(v)) return 0;
    *out = v;
    return 1;
}

static int object_id(const char *w, int *out)
{
    char *end;
    errno = 0;
    long v = strtol(w, &end, 10);
    if (end == w || *end || errno || v < 0 || v > 0x7fffffffL) return 0;
    *out = (int)v;
    return 1;
}

typedef struct cmd {
    const char *name;
    vw_edit_op op;
    int min, max; /* operand words */
    const char *usage;
} cmd;

static const cmd cmds[] = {
    {"move", VW_EDIT_MOVE, 4, 4, "move ID dx dy dz"},
    {"moveto", VW_EDIT_MOVETO, 4, 4, "moveto ID x y z"},
    {"rotate", VW_EDIT_ROTATE, 5, 5, "rotate ID ax ay az DEGREES"},
    {"add", VW_EDIT_ADD, 5, 6, "add sphere x y z r [MATERIAL]"},
    {"remove", VW_EDIT_REMOVE, 1, 1, "remove ID"},
    {"check", VW_EDIT_CHECK, 1, 1, "check on|off"},
    {"sweep", VW_EDIT_SWEEP, 1, 1, "sweep on|off"},
    {"frame", VW_EDIT_FRAME, 0, 0, "frame"},
    {"balance", VW_EDIT_BALANCE, 0, 0, "balance"},
};

vw_status vw_edit_parse(const char *line, const char *name, int lineno, vw_edit *out,
                        char *err, size_t errlen)
{
    if (!line || !out) return VW_E_INVAL;
    memset(out, 0, sizeof *out);
    out->line = lineno;
    out->material = -1;
    char buf[512];
    size_t len = strcspn(line, "#\r\n");
    if (len >= sizeof buf) return fail(err, errlen, name, lineno, "line too long");
    memcpy(buf, line, len);
    buf[len] = 0;
    /* Words cut by hand, not by strtok: its hidden state is shared with the caller (who
       may be cutting a script into lines with strtok, and found the rest gone after the
       first line) and with every other thread. */
    char *w[MAX_WORDS + 1];
    int n = 0;
    for (char *q = buf;;) {
        while (*q && strchr(" \t\v\f", *q)) q++;
        if (!*q) break;
        if (n == MAX_WORDS + 1) return fail(err, errlen, name, lineno, "too many words");
        w[n++] = q;
        while (*q && !strchr(" \t\v\f", *q)) q++;
        if (*q) *q++ = 0;
    }
    if (n == 0) return VW_OK; /* blank or comment */
    const cmd *c = NULL;
    for (size_t i = 0; i < sizeof cmds / sizeof cmds[0]; i++)
        if (!strcmp(w[0], cmds[i].name)) c = &cmds[i];
    char sb[SHOWN_BUF];
    if (!c) return fail(err, errlen, name, lineno, "unknown command '%s'", shown(w[0], sb));
    if (n - 1 < c->min || n - 1 > c->max)
        return fail(err, errlen, name, lineno, "expected '%s'", c->usage);
    out->op = c->op;
    switch (c->op) {
    case VW_EDIT_MOVE:
    case VW_EDIT_MOVETO:
    case VW_EDIT_ROTATE:
    case VW_EDIT_REMOVE: {
        if (!object_id(w[1], &out->id))
            return fail(err, errlen, name, lineno, "bad object id '%s'", shown(w[1], sb));
        for (int k = 2; k < n; k++)
            if (!number(w[k], &out->v[k - 2]))
                return fail(err, errlen, name, lineno, "bad number '%s' (expected '%s')",
                            shown(w[k], sb), c->usage);
        if (c->op == VW_EDIT_ROTATE &&
            !(out->v[0] != 0 || out->v[1] != 0 || out->v[2] != 0))
            return fail(err, errlen, name, lineno, "rotation axis is zero");
        break;
    }
    case VW_EDIT_ADD:
        if (strcmp(w[1], "sphere"))
            return fail(err, errlen, name, lineno, "can only add a sphere, not '%s'",
                        shown(w[1], sb));
        for (int k = 2; k < 6; k++)
            if (!number(w[k], &out->v[k - 2]))
                return fail(err, errlen, name, lineno, "bad number '%s' (expected '%s')",
                            shown(w[k], sb), c->usage);
        if (!(out->v[3] > 0)) return fail(err, errlen, name, lineno, "sphere radius must be > 0");
        if (n == 7 && !object_id(w[6], &out->material))
            return fail(err, errlen, name, lineno, "bad material index '%s'", shown(w[6], sb));
        break;
    case VW_EDIT_CHECK:
    case VW_EDIT_SWEEP:
        if (!strcmp(w[1], "on"))
            out->on = 1;
        else if (!strcmp(w[1], "off"))
            out->on = 0;
        else
            return fail(err, errlen, name, lineno, "expected '%s'", c->usage);
        break;
    default:
        break;
    }
    return VW_OK;
}
