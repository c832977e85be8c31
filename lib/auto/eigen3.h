/* A symmetric 3x3 matrix's eigen decomposition (eigen3.c). Internal, not installed. */
#ifndef RSMOOTH_EIGEN3_H
#define RSMOOTH_EIGEN3_H

/* The eigenvalues of the symmetric m, ascending, and their unit eigenvectors (vectors[k], a row,
 * belongs to values[k]). */
void rs_symmetric_eigen3(double m[3][3], double values[3], double vectors[3][3]);

#endif /* RSMOOTH_EIGEN3_H */
