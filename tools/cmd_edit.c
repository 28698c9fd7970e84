/* cmd_edit.c - vwalls edit: the edit language (docs/edit-language.md) read interactively
 * from stdin; every edit is answered at once, 'frame' renders to the -o pattern. The
 * session is the one vwalls animate runs (cmd_animate.c).
 */
#include "commands.h"

int vw_cmd_edit(int argc, char **argv) { return vw_anim_main("edit", argc, argv); }
