/* mat3.h (private): the little 3 x 3 matrix arithmetic the dynamics share. */
#ifndef PD_MAT3_H
#define PD_MAT3_H

#include "base/vec3.h"

/* C before C23 will not pass a double[3][3] where a const one is expected
 * without a cast: CONST_M3(M) is that cast. */
#define CONST_M3(m) ((const double(*)[3])(m))

/* M v. */
static inline pd_vec3 m3_vec(const double M[3][3], pd_vec3 v)
{
    return v3(M[0][0] * v.x + M[0][1] * v.y + M[0][2] * v.z,
              M[1][0] * v.x + M[1][1] * v.y + M[1][2] * v.z,
              M[2][0] * v.x + M[2][1] * v.y + M[2][2] * v.z);
}

/* Eigen-decomposition of a symmetric 3x3 matrix by cyclic Jacobi rotations:
 * A = V diag(eval) V^T, eval ascending, the columns of V orthonormal and
 * right-handed (det V = +1). */
void pd_sym_eigen3(const double A[3][3], double eval[3], double V[3][3]);

#endif
