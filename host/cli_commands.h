/* The rsmooth command's subcommands besides smoothing; each takes argv from its own name on. */
#ifndef RSMOOTH_CLI_COMMANDS_H
#define RSMOOTH_CLI_COMMANDS_H

/* rsmooth compare RESULT TRUTH [--json]: error metrics of a result against its ground truth.
 * Exit status 0, 2 (bad usage; a file unreadable, malformed or not matching the other), 1. */
int cli_compare_main(int argc, char **argv);

/* rsmooth noise IN OUT --sigma S [...]: reproducible Gaussian or impulsive noise. */
int cli_noise_main(int argc, char **argv);

/* rsmooth render IN... -o OUT.png [...]: flat-shaded pictures of meshes side by side (PNG). */
int cli_render_main(int argc, char **argv);

#endif
