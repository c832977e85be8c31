/* rsmooth-mpi's check that every rank runs the same job: the ranks write disjoint rows of one
 * shared file, so a rank given another input, other parameters, another cap (other pieces) or
 * another output would leave vertices unsmoothed or write garbage with exit 0. */
#ifndef RSMOOTH_MPI_AGREE_H
#define RSMOOTH_MPI_AGREE_H

#include "cli_options.h"

/* Compares opt's input file (size, modification time, the first 64 KiB and 16 samples of 4 KiB),
 * its parameters (and the library's version), --max-memory, the output (with --force /
 * --in-place) and the --mask file (as the input) across the ranks of MPI_COMM_WORLD (collective),
 * byte for byte with rank 0's. -1 when all agree; else rank 0 prints which rank differs in what,
 * and every rank returns the usage exit status. --device, --quiet and --json may differ. */
int mpi_agree(const options *opt, int rank, int ranks);

#endif
