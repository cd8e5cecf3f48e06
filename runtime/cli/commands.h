/* commands.h -- the subcommands of bin/swim. Each returns the process exit status:
 * 0 success, 1 a run that failed or stopped early (its output kept), 2 bad input. */
#ifndef SWIM_COMMANDS_H
#define SWIM_COMMANDS_H

int swim_cmd_inspect(int argc, char **argv);
int swim_cmd_run(int argc, char **argv);
int swim_cmd_plot(int argc, char **argv);
int swim_cmd_flow(int argc, char **argv);
int swim_cmd_animate(int argc, char **argv);
int swim_cmd_sweep(int argc, char **argv);
int swim_cmd_floquet(int argc, char **argv);
int swim_cmd_periodic(int argc, char **argv);
int swim_cmd_continue(int argc, char **argv);
int swim_cmd_optimize(int argc, char **argv);
int swim_cmd_cache(int argc, char **argv);
int swim_cmd_export(int argc, char **argv);

#endif
