/* eigen3.c: the eigen-decomposition of a symmetric 3x3 matrix (mat3.h). */
#include <math.h>
#include <string.h>
#include "base/mat3.h"

/* Jacobi sweeps before giving up. A 3x3 symmetric matrix converges
 * quadratically once the off-diagonal part is small; 6 sweeps reach round-off
 * from any start, 50 is a bound that is never reached. */
enum { JACOBI_MAX_SWEEPS = 50 };

/* Own Jacobi rather than GSL's gsl_eigen_symmv: it needs no workspace (the
 * GSL routine allocates one), it is ~40 lines, and Jacobi rotations are the
 * method with the best accuracy on small symmetric matrices: each eigenvalue
 * to round-off relative to the matrix norm and orthonormal vectors to
 * round-off (Golub & Van Loan, Matrix Computations, sec. 8.5; Rutishauser's
 * formulation of the rotation angle for stability). */
void pd_sym_eigen3(const double Ain[3][3], double eval[3], double V[3][3])
{
    double A[3][3];
    memcpy(A, Ain, sizeof A);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            V[i][j] = i == j ? 1.0 : 0.0;
    for (int sweep = 0; sweep < JACOBI_MAX_SWEEPS; sweep++) {
        double off = fabs(A[0][1]) + fabs(A[0][2]) + fabs(A[1][2]);
        if (off == 0.0)
            break;
        for (int p = 0; p < 2; p++)
            for (int q = p + 1; q < 3; q++) {
                double apq = A[p][q];
                if (apq == 0.0)
                    continue;
                /* t = tan of the rotation angle, the smaller root of
                 * t^2 + 2 theta t - 1 = 0, so |angle| <= 45 degrees. */
                double theta = (A[q][q] - A[p][p]) / (2.0 * apq);
                double t = (theta >= 0.0 ? 1.0 : -1.0) / (fabs(theta) + sqrt(theta * theta + 1.0));
                if (!isfinite(theta))
                    t = 0.5 / theta; /* huge theta: t ~ 1/(2 theta) */
                double c = 1.0 / sqrt(t * t + 1.0), s = t * c;
                for (int k = 0; k < 3; k++) { /* A <- A G */
                    double akp = A[k][p], akq = A[k][q];
                    A[k][p] = c * akp - s * akq;
                    A[k][q] = s * akp + c * akq;
                }
                for (int k = 0; k < 3; k++) { /* A <- G^T A */
                    double apk = A[p][k], aqk = A[q][k];
                    A[p][k] = c * apk - s * aqk;
                    A[q][k] = s * apk + c * aqk;
                }
                A[p][q] = A[q][p] = 0.0; /* zero by construction; drop its round-off */
                for (int k = 0; k < 3; k++) {
                    double vkp = V[k][p], vkq = V[k][q];
                    V[k][p] = c * vkp - s * vkq;
                    V[k][q] = s * vkp + c * vkq;
                }
            }
    }
    double d[3] = {A[0][0], A[1][1], A[2][2]};
    int order[3] = {0, 1, 2};
    for (int i = 0; i < 3; i++)
        for (int j = i + 1; j < 3; j++)
            if (d[order[j]] < d[order[i]]) {
                int tmp = order[i];
                order[i] = order[j];
                order[j] = tmp;
            }
    double W[3][3];
    for (int j = 0; j < 3; j++) {
        eval[j] = d[order[j]];
        for (int i = 0; i < 3; i++)
            W[i][j] = V[i][order[j]];
    }
    double det = W[0][0] * (W[1][1] * W[2][2] - W[1][2] * W[2][1]) -
                 W[0][1] * (W[1][0] * W[2][2] - W[1][2] * W[2][0]) +
                 W[0][2] * (W[1][0] * W[2][1] - W[1][1] * W[2][0]);
    if (det < 0.0)
        for (int i = 0; i < 3; i++)
            W[i][2] = -W[i][2];
    memcpy(V, W, sizeof W);
}
