/* tools/commands.h - the subcommands of the vwalls command, one file each (cmd_*.c).
 * Each takes the arguments after the subcommand name (argv[0] is the subcommand) and
 * returns the exit status: 0 success, 2 bad input or usage, 1 any other failure.
 */
#ifndef VW_TOOLS_COMMANDS_H
#define VW_TOOLS_COMMANDS_H

int vw_cmd_example_pairs(int argc, char **argv);
int vw_cmd_example_components(int argc, char **argv);
int vw_cmd_render(int argc, char **argv);

int vw_cmd_gen(int argc, char **argv);
int vw_cmd_info(int argc, char **argv);
int vw_cmd_radiosity(int argc, char **argv);
int vw_cmd_animate(int argc, char **argv);
int vw_cmd_edit(int argc, char **argv);
int vw_cmd_bench(int argc, char **argv);
/* The session of animate and edit (cmd_animate.c); cmd is "animate" or "edit". */
int vw_anim_main(const char *cmd, int argc, char **argv);

/* --farm of render, animate and edit (cmd_render.c): the value v as an rt_farm, or -1 for
   auto, in *farm; reports a bad value and returns nonzero. */
int vw_cli_farm(const char *cmd, const char *v, int *farm);
/* --farm auto resolved: every worker holds every cell (all), unless a balancer or a
   mapping was asked for (planned), whose plan then runs as mapped (idle). */
int vw_cli_farm_resolve(int farm, int planned);

#endif
