/* rsmooth-bench best (bench_best.c): the best mode against the paper filter, stage by stage. */
#ifndef RSMOOTH_BENCH_BEST_H
#define RSMOOTH_BENCH_BEST_H

/* argv[1] is "best"; returns the exit status. */
int bench_best(int argc, char **argv);

#endif /* RSMOOTH_BENCH_BEST_H */
