/* compare.c: the self-crossing search against another build of it, mesh by
 * mesh: the same answer (crossing or not) on every mesh of a randomized set,
 * and on every mesh file named. Built and run by scripts/selfx-compare.sh,
 * which compiles the other version's mesh_selfx.c (by default that of
 * 9f2cb89, before the tree of this one) with its entry point renamed
 * old_self_crossing.
 *
 * The set (seeded): random small-integer triangle soups; meshes of small
 * triangles on a random walk of integer points (corners and edges shared
 * often); closed UV spheres and fanned rods of 3 to 22 sides, turned at
 * random, one vertex pushed in by up to 2.5 radii; each of the last two
 * scaled by 1e-3 to 1e3 and moved up to 1e3 sizes off the origin. Then a
 * tenth as many pairs of noisy UV spheres apart, placed the same way. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "posedrop/posedrop.h"
#include "mesh/mesh_internal.h"

pd_status old_self_crossing(const pd_mesh *m, int *ta, int *tb, pd_vec3 *at, size_t *tested);

static unsigned long long rs = 88172645463325252ULL;
static double uni(void)
{
    rs ^= rs << 13;
    rs ^= rs >> 7;
    rs ^= rs << 17;
    return (double)(rs >> 11) * 0x1p-53;
}

static int mismatches, crossing, total;

static void compare(const pd_mesh *m, const char *what, int i)
{
    int ta, tb, oa, ob;
    pd_vec3 at;
    pd_status s1 = pd_mesh_self_crossing(m, NULL, &ta, &tb, &at, NULL);
    pd_status s2 = old_self_crossing(m, &oa, &ob, &at, NULL);
    total++;
    crossing += oa >= 0;
    if (s1 != s2 || (ta >= 0) != (oa >= 0)) {
        mismatches++;
        printf("MISMATCH %s %d: new %d (%d %d), old %d (%d %d)\n", what, i, s1, ta, tb, s2, oa, ob);
    }
}

static void soup(int i, int nt, int R)
{
    pd_vec3 v[96];
    int tri[32][3];
    for (int k = 0; k < 3 * nt; k++)
        v[k] = (pd_vec3){(int)(uni() * (2 * R + 1)) - R, (int)(uni() * (2 * R + 1)) - R,
                         (int)(uni() * (2 * R + 1)) - R};
    for (int t = 0; t < nt; t++)
        for (int k = 0; k < 3; k++)
            tri[t][k] = uni() < 0.3 && t > 0 ? (int)(uni() * 3 * t) : 3 * t + k;
    pd_mesh m = {3 * nt, v, nt, tri};
    compare(&m, "soup", i);
}

static void walk(int i, int nv, int nt)
{
    pd_vec3 *v = malloc(sizeof *v * (size_t)nv);
    int(*tri)[3] = malloc(sizeof *tri * (size_t)nt);
    for (int k = 0; k < nv; k++)
        v[k] = (pd_vec3){(k ? v[k - 1].x : 0) + (int)(uni() * 5) - 2,
                         (k ? v[k - 1].y : 0) + (int)(uni() * 5) - 2,
                         (k ? v[k - 1].z : 0) + (int)(uni() * 5) - 2};
    for (int t = 0; t < nt; t++) {
        int base = (int)(uni() * nv);
        for (int k = 0; k < 3; k++)
            tri[t][k] = k == 0 ? base : (base + 1 + (int)(uni() * 4)) % nv;
    }
    pd_mesh m = {nv, v, nt, tri};
    compare(&m, "walk", i);
    free(v);
    free(tri);
}

/* Turned at random, scaled and moved, one vertex pushed towards the centre
 * by up to 2.5 radii (through the far side: a fold that crosses). */
static void place(pd_vec3 *v, int nv, double radius)
{
    double a = uni() * 2 * M_PI, b = acos(2 * uni() - 1), c = uni() * 2 * M_PI;
    double s = pow(10.0, 6 * uni() - 3), off = 1e3 * s * (2 * uni() - 1);
    int push = (int)(uni() * nv);
    double depth = 2.5 * radius * uni();
    pd_vec3 p = v[push];
    double n = sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    if (n > 0)
        v[push] = (pd_vec3){p.x - depth * p.x / n, p.y - depth * p.y / n, p.z - depth * p.z / n};
    for (int k = 0; k < nv; k++) {
        pd_vec3 q = v[k];
        double x = cos(a) * q.x - sin(a) * q.y, y = sin(a) * q.x + cos(a) * q.y, z = q.z;
        double y2 = cos(b) * y - sin(b) * z, z2 = sin(b) * y + cos(b) * z;
        double x3 = cos(c) * x - sin(c) * z2, z3 = sin(c) * x + cos(c) * z2;
        v[k] = (pd_vec3){s * x3 + off, s * y2 + off, s * z3 + off};
    }
}

/* The triangles of a UV sphere of nu x (nw - 1) corners and two poles
 * (the last two), its corners numbered from o, written from tri[t] on;
 * the next free triangle. */
static int sphere_faces(int (*tri)[3], int t, int o, int nu, int nw)
{
    int nv = nu * (nw - 1) + 2;
    for (int j = 0; j < nu; j++) {
        int jn = (j + 1) % nu;
        tri[t][0] = o + nv - 2, tri[t][1] = o + j, tri[t][2] = o + jn, t++;
        int a = (nw - 2) * nu;
        tri[t][0] = o + nv - 1, tri[t][1] = o + a + jn, tri[t][2] = o + a + j, t++;
        for (int r = 0; r + 1 < nw - 1; r++) {
            int p = o + r * nu, q = o + (r + 1) * nu;
            tri[t][0] = p + j, tri[t][1] = q + j, tri[t][2] = q + jn, t++;
            tri[t][0] = p + j, tri[t][1] = q + jn, tri[t][2] = p + jn, t++;
        }
    }
    return t;
}

static void uv_sphere(int i, int nu, int nw)
{
    int nv = nu * (nw - 1) + 2, nt = 2 * nu * (nw - 1);
    pd_vec3 *v = malloc(sizeof *v * (size_t)nv);
    int(*tri)[3] = malloc(sizeof *tri * (size_t)nt);
    for (int r = 1; r < nw; r++)
        for (int j = 0; j < nu; j++) {
            double th = M_PI * r / nw, ph = 2 * M_PI * j / nu;
            v[(r - 1) * nu + j] = (pd_vec3){sin(th) * cos(ph), sin(th) * sin(ph), cos(th)};
        }
    v[nv - 2] = (pd_vec3){0, 0, 1};
    v[nv - 1] = (pd_vec3){0, 0, -1};
    int t = sphere_faces(tri, 0, 0, nu, nw);
    place(v, nv, 1.0);
    pd_mesh m = {nv, v, t, tri};
    compare(&m, "sphere", i);
    free(v);
    free(tri);
}

static void rod(int i, int n)
{
    int nv = 2 * n, nt = 2 * (2 * n - 2), t = 0;
    pd_vec3 *v = malloc(sizeof *v * (size_t)nv);
    int(*tri)[3] = malloc(sizeof *tri * (size_t)nt);
    double len = 1.0 + 20.0 * uni();
    for (int e = 0; e < 2; e++)
        for (int k = 0; k < n; k++) {
            double a = 2 * M_PI * k / n;
            v[e * n + k] = (pd_vec3){e * len - 0.5 * len, cos(a), sin(a)};
        }
    for (int k = 0; k < n; k++) {
        int j = (k + 1) % n;
        tri[t][0] = k, tri[t][1] = j, tri[t][2] = n + j, t++;
        tri[t][0] = k, tri[t][1] = n + j, tri[t][2] = n + k, t++;
    }
    for (int k = 1; k < n - 1; k++) {
        tri[t][0] = 0, tri[t][1] = k + 1, tri[t][2] = k, t++;
        tri[t][0] = n, tri[t][1] = n + k, tri[t][2] = n + k + 1, t++;
    }
    place(v, nv, 1.0);
    pd_mesh m = {nv, v, t, tri};
    compare(&m, "rod", i);
    free(v);
    free(tri);
}

/* Two noisy UV spheres 3 radii apart (each corner at a radius drawn in
 * [0.6, 1]), then placed as above, which pushes one corner of either
 * towards the first one's centre: a part that is not star-shaped, whose
 * check searches only the triangles of one sphere that the other hides
 * from a point inside it, and the other's. */
static void sphere_pair(int i, int nu, int nw)
{
    int nv1 = nu * (nw - 1) + 2, nt1 = 2 * nu * (nw - 1), nv = 2 * nv1, t = 0;
    pd_vec3 *v = malloc(sizeof *v * (size_t)nv);
    int(*tri)[3] = malloc(sizeof *tri * 2 * (size_t)nt1);
    for (int h = 0; h < 2; h++) {
        int o = h * nv1;
        for (int r = 1; r < nw; r++)
            for (int j = 0; j < nu; j++) {
                double th = M_PI * r / nw, ph = 2 * M_PI * j / nu, rr = 0.6 + 0.4 * uni();
                v[o + (r - 1) * nu + j] = (pd_vec3){rr * sin(th) * cos(ph) + 3.0 * h,
                                                    rr * sin(th) * sin(ph), rr * cos(th)};
            }
        v[o + nv1 - 2] = (pd_vec3){3.0 * h, 0, 0.6 + 0.4 * uni()};
        v[o + nv1 - 1] = (pd_vec3){3.0 * h, 0, -0.6 - 0.4 * uni()};
        t = sphere_faces(tri, t, o, nu, nw);
    }
    place(v, nv, 1.0);
    pd_mesh m = {nv, v, t, tri};
    compare(&m, "pair", i);
    free(v);
    free(tri);
}

int main(int argc, char **argv)
{
    int n = argc > 1 ? atoi(argv[1]) : 20000;
    for (int i = 0; i < n; i++) {
        double u = uni();
        if (i % 2 == 0) {
            if (u < 0.5)
                soup(i, 2 + (int)(uni() * 10), 1 + (int)(uni() * 3));
            else
                walk(i, 40 + (int)(uni() * 400), 12 + (int)(uni() * 300));
        } else if (u < 0.5) {
            uv_sphere(i, 3 + (int)(uni() * 20), 2 + (int)(uni() * 20));
        } else {
            rod(i, 3 + (int)(uni() * 20));
        }
    }
    printf("random set: %d meshes, %d cross (old), %d mismatches\n", total, crossing, mismatches);
    /* Pairs of spheres, a tenth as many, after the set above (which they
     * leave as it was). */
    int t0 = total, c0 = crossing, m0 = mismatches;
    for (int i = 0; i < n / 10; i++)
        sphere_pair(i, 6 + (int)(uni() * 40), 4 + (int)(uni() * 40));
    printf("pairs of spheres: %d meshes, %d cross (old), %d mismatches\n", total - t0,
           crossing - c0, mismatches - m0);
    for (int a = 2; a < argc; a++) {
        pd_mesh *m = NULL;
        if (pd_mesh_read(argv[a], NULL, &m, NULL) != PD_OK)
            continue;
        int before = mismatches;
        compare(m, argv[a], 0);
        printf("%s: %s\n", argv[a], mismatches == before ? "same" : "DIFFERENT");
        pd_mesh_free(m);
    }
    return mismatches != 0;
}
