/* sweep.h: `wobble sweep` and `wobble collect` (docs/cli.md, "Sweeps"), called by main.c
 * with the whole command line (argv[1] is the command); both return the exit code. */
#ifndef WOBBLE_CLI_SWEEP_H
#define WOBBLE_CLI_SWEEP_H

int wb_cmd_sweep(int argc, char **argv);    /* sweep.c */
int wb_cmd_collect(int argc, char **argv);  /* collect.c */

#endif
