/* test_mesh.c: reading OFF, STL and OBJ, format detection, units, bad input,
 * and welding.
 *
 * Coordinates written as short decimals are compared exactly: strtod rounds
 * correctly, so the reader must return the same double as the C literal.
 * Every malformed input must fail with its own status and a message that
 * names the file and, for text formats, the line. */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "check.h"
#include "base/predicates.h"
#include "base/vec3.h"
#include "mesh/mesh_internal.h"
#include "posedrop/mesh.h"
#include "shapes.h"
#include "suites.h"

static const char *const exact = "exact: correctly rounded decimal";

static pd_status parse_as(const char *text, const char *name, pd_mesh_format format,
                          pd_units units, pd_mesh **m, pd_diag *d)
{
    pd_mesh_read_options o;
    pd_mesh_read_options_default(&o);
    o.format = format;
    o.units = units;
    pd_diag_init(d);
    return pd_mesh_parse(text, strlen(text), name, &o, m, d);
}

static pd_mesh *parse_ok(const char *text, const char *name)
{
    pd_mesh *m = NULL;
    pd_diag d;
    pd_status st = parse_as(text, name, PD_FORMAT_AUTO, PD_UNITS_M, &m, &d);
    CHECK_STATUS(st, PD_OK);
    if (st != PD_OK) {
        printf("     %s: %s\n", name, d.message);
        return NULL;
    }
    return m;
}

/* Bad input: the expected status, a message containing needle, and *mesh
 * left as it was. */
static void expect_bad_as(const char *text, const char *name, pd_mesh_format format,
                          pd_status expected, const char *needle)
{
    pd_mesh sentinel_mesh = {0};
    pd_mesh *m = &sentinel_mesh;
    pd_diag d;
    pd_status st = parse_as(text, name, format, PD_UNITS_M, &m, &d);
    CHECK_STATUS(st, expected);
    CHECK(m == &sentinel_mesh);
    int found = strstr(d.message, needle) != NULL;
    CHECK(found);
    if (!found || st != expected)
        printf("     wanted '%s' in: %s\n", needle, d.message);
    if (st == PD_OK && m != &sentinel_mesh)
        pd_mesh_free(m);
}

static void expect_bad(const char *text, const char *name, pd_status expected, const char *needle)
{
    expect_bad_as(text, name, PD_FORMAT_AUTO, expected, needle);
}

static int tri_is(const pd_mesh *m, int t, int a, int b, int c)
{
    return m->tris[t][0] == a && m->tris[t][1] == b && m->tris[t][2] == c;
}

/* --- OFF ------------------------------------------------------------------- */

static const char tetra_off[] =
    "# a tetrahedron\n"
    "OFF\n"
    "\n"
    "4 4 6  # counts\n"
    "0 0 0\n"
    "1.5 0 0   # trailing comment\n"
    "# full-line comment between vertices\n"
    "0 2.25 0\n"
    "0 0 -0.125\n"
    "3 0 2 1\n"
    "3 0 1 3\n"
    "\n"
    "3 0 3 2\n"
    "3 1 2 3\n";

static void test_off(void)
{
    pd_mesh *m = parse_ok(tetra_off, "tetra.off");
    if (m) {
        CHECK_INT(m->nverts, 4);
        CHECK_INT(m->ntris, 4);
        CHECK_NEAR(m->verts[1].x, 1.5, 0.0, exact);
        CHECK_NEAR(m->verts[2].y, 2.25, 0.0, exact);
        CHECK_NEAR(m->verts[3].z, -0.125, 0.0, exact);
        CHECK(tri_is(m, 0, 0, 2, 1) && tri_is(m, 3, 1, 2, 3));
        pd_mesh_free(m);
    }

    /* Header variants: counts on the keyword's line, colours, normals and
     * texture coordinates after the coordinates, colours after faces. */
    static const char *const variants[] = {
        "OFF 4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n",
        "COFF\n4 2 0\n0 0 0 1 0 0 1\n1 0 0 1 0 0 1\n0 1 0 1 0 0 1\n0 0 1 1 0 0 1\n"
        "3 0 1 2 255 0 0\n3 0 1 3 0.5 0.5 0.5 1\n",
        "NOFF\n4 2\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n0 0 1 0 0 1\n3 0 1 2\n3 0 1 3\n",
        "CNOFF\n4 2 0\n0 0 0 0 0 1 1 1 1 1\n1 0 0 0 0 1 1 1 1 1\n0 1 0 0 0 1 1 1 1 1\n"
        "0 0 1 0 0 1 1 1 1 1\n3 0 1 2\n3 0 1 3\n",
        "STOFF\n4 2 0\n0 0 0 0 0\n1 0 0 1 0\n0 1 0 0 1\n0 0 1 1 1\n3 0 1 2\n3 0 1 3\n",
        "nOFF 3\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n",
        "\xEF\xBB\xBFOFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n", /* UTF-8 BOM */
        "OFF\r\n4 2 0\r\n0 0 0\r\n1 0 0\r\n0 1 0\r\n0 0 1\r\n3 0 1 2\r\n3 0 1 3", /* CRLF, no final newline */
    };
    for (size_t i = 0; i < sizeof variants / sizeof variants[0]; i++) {
        m = parse_ok(variants[i], "variant.off");
        if (!m)
            continue;
        CHECK_INT(m->nverts, 4);
        CHECK_INT(m->ntris, 2);
        CHECK_NEAR(m->verts[3].z, 1.0, 0.0, exact);
        CHECK(tri_is(m, 1, 0, 1, 3));
        pd_mesh_free(m);
    }

    /* Polygons are fanned from their first vertex: a quad gives 2 triangles,
     * a pentagon 3, all sharing that vertex. */
    m = parse_ok("OFF\n5 2 0\n0 0 0\n1 0 0\n2 1 0\n1 2 0\n0 1 0\n5 0 1 2 3 4\n4 4 3 2 1\n", "poly.off");
    if (m) {
        CHECK_INT(m->ntris, 5);
        CHECK(tri_is(m, 0, 0, 1, 2) && tri_is(m, 1, 0, 2, 3) && tri_is(m, 2, 0, 3, 4));
        CHECK(tri_is(m, 3, 4, 3, 2) && tri_is(m, 4, 4, 2, 1));
        pd_mesh_free(m);
    }
}

static void test_off_bad(void)
{
    /* The example of the CLI test: a non-numeric coordinate on line 6. */
    expect_bad("OFF\n# a comment\n4 4 0\n0 0 0\n1 0 0\n0 x 0\n0 0 1\n3 0 1 2\n3 0 1 3\n3 0 2 3\n3 1 2 3\n",
               "bad.off", PD_ERR_PARSE, "bad.off:6: expected a coordinate, found 'x'");
    expect_bad("OFF\n4 1 0\n0 0 0\n1 0\n0 1 0\n0 0 1\n3 0 1 2\n", "short.off", PD_ERR_PARSE,
               "short.off:4: expected 3 coordinates, found 2");
    expect_bad("OFF\n4 1 0\n0 0 0\n1 0 nan\n0 1 0\n0 0 1\n3 0 1 2\n", "nan.off", PD_ERR_NONFINITE,
               "nan.off:4:");
    expect_bad("OFF\n4 1 0\n0 0 0\n1 0 0\n0 inf 0\n0 0 1\n3 0 1 2\n", "inf.off", PD_ERR_NONFINITE,
               "inf.off:5:");
    expect_bad("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1e999\n3 0 1 2\n", "big.off", PD_ERR_NONFINITE,
               "big.off:6:");
    expect_bad("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 4\n", "idx.off", PD_ERR_RANGE,
               "idx.off:7: vertex index 4 out of range");
    expect_bad("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 -1 2\n", "neg.off", PD_ERR_RANGE,
               "neg.off:7:");
    expect_bad("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n2 0 1\n", "two.off", PD_ERR_PARSE,
               "two.off:7: face with 2 vertices");
    /* Faces too short for a triangle are said to be so, not taken for a
     * file cut short ("truncated file?"). */
    expect_bad("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 0\n1 1\n1 2\n1 3\n", "one.off",
               PD_ERR_PARSE, "one.off:7: face with 1 vertices (at least 3 needed)");
    expect_bad("OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n2 0 1\n2 1 2\n2 2 3\n2 3 0\n", "two4.off",
               PD_ERR_PARSE, "two4.off:7: face with 2 vertices");
    expect_bad("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n4 0 1 2\n", "few.off", PD_ERR_PARSE,
               "few.off:7: expected 4 vertex indices, found 3");
    expect_bad("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 z\n", "tok.off", PD_ERR_PARSE,
               "tok.off:7: expected a vertex index, found 'z'");
    expect_bad("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n70000 0 1 2\n", "huge.off", PD_ERR_RANGE,
               "huge.off:7: face with 70000 vertices");
    expect_bad("OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n3 0 1 3\n", "faces.off",
               PD_ERR_PARSE, "faces.off:");
    expect_bad("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\ngarbage here\n", "tail.off",
               PD_ERR_PARSE, "tail.off:8: expected end of file");
    expect_bad("OFF\n4 1 0 7\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 1 2\n", "cnt.off", PD_ERR_PARSE,
               "cnt.off:2:");
    expect_bad("OFF\n-4 1 0\n", "negc.off", PD_ERR_PARSE, "negc.off:2: expected the vertex count");
    expect_bad("OFF\n0 0 0\n", "empty.off", PD_ERR_PARSE, "no faces");
    expect_bad("OFF\n", "hdr.off", PD_ERR_PARSE, "hdr.off:");
    expect_bad("", "nothing.off", PD_ERR_PARSE, "nothing.off");
    expect_bad("OFX\n4 1 0\n", "kw.off", PD_ERR_PARSE, "kw.off:1: expected OFF header");
    /* Lying counts: refused before any allocation, by the limit or by the
     * bytes that follow. */
    expect_bad("OFF\n2000000000 2000000000 0\n0 0 0\n", "liar.off", PD_ERR_RANGE, "liar.off:2:");
    expect_bad("OFF\n1000000 1 0\n0 0 0\n", "liar2.off", PD_ERR_PARSE, "bytes");
    expect_bad("OFF\n99999999999999999999999 1 0\n", "liar3.off", PD_ERR_RANGE, "liar3.off:2:");
    /* Variants not read. */
    expect_bad("4OFF\n4 1 0\n0 0 0 1\n", "h.off", PD_ERR_FORMAT, "4-D");
    expect_bad("OFF BINARY\n\x00\x00", "bin.off", PD_ERR_FORMAT, "binary OFF");
    expect_bad("nOFF 4\n4 1 0\n", "n4.off", PD_ERR_FORMAT, "dimension 4");
}

/* --- STL ------------------------------------------------------------------- */

static const char tetra_stl[] =
    "solid tetra made by hand\n"
    "  facet normal 0 0 -1\n"
    "    outer loop\n"
    "      vertex 0 0 0\n"
    "      vertex 0 1 0\n"
    "      vertex 1 0 0\n"
    "    endloop\n"
    "  endfacet\n"
    "  FACET NORMAL 0 -1 0\n"
    "    OUTER LOOP\n"
    "      VERTEX -0.0 0 0\n" /* -0 and 0 are one vertex */
    "      VERTEX 1 0 0\n"
    "      VERTEX 0 0 1\n"
    "    ENDLOOP\n"
    "  ENDFACET\n"
    "endsolid tetra made by hand\n"
    "solid second\n"
    "  facet normal nan nan nan\n"
    "    outer loop\n"
    "      vertex 0 0 0\n"
    "      vertex 0 0 1\n"
    "      vertex 0 1 0\n"
    "    endloop\n"
    "  endfacet\n"
    "  facet normal 1 1 1 outer loop vertex 1 0 0 vertex 0 1 0 vertex 0 0 1 endloop endfacet\n"
    "endsolid\n";

static void test_stl_ascii(void)
{
    pd_mesh *m = parse_ok(tetra_stl, "tetra.stl");
    if (m) {
        /* 12 corners, 4 distinct points: bit-identical corners are merged. */
        CHECK_INT(m->nverts, 4);
        CHECK_INT(m->ntris, 4);
        CHECK(tri_is(m, 0, 0, 1, 2) && tri_is(m, 1, 0, 2, 3) && tri_is(m, 3, 2, 1, 3));
        CHECK_NEAR(m->verts[1].y, 1.0, 0.0, exact);
        pd_mesh_free(m);
    }
    /* A non-finite coordinate named as what was expected there. */
    expect_bad("solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 nan\n"
               "vertex 0 1 0\nendloop\nendfacet\nendsolid s\n", "nan.stl", PD_ERR_NONFINITE,
               "nan.stl:5: expected a z coordinate (a finite number), found 'nan'");
    /* Near-duplicates are for pd_mesh_weld, not the reader. */
    m = parse_ok("solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
                 "endloop\nendfacet\nfacet normal 0 0 1\nouter loop\nvertex 0 0 1e-12\n"
                 "vertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid s\n", "near.stl");
    if (m) {
        CHECK_INT(m->nverts, 4);
        pd_mesh_free(m);
    }

    const char *head = "solid s\nfacet normal 0 0 1\nouter loop\n";
    char buf[512];
    snprintf(buf, sizeof buf, "%svertex 0 0 0\nvertex 1 x 0\n", head);
    expect_bad(buf, "a.stl", PD_ERR_PARSE, "a.stl:5: expected a y coordinate, found 'x'");
    snprintf(buf, sizeof buf, "%svertex 0 0 0\nvertex 1 0 inf\n", head);
    expect_bad(buf, "b.stl", PD_ERR_NONFINITE, "b.stl:5:");
    snprintf(buf, sizeof buf, "%svertex 0 0 0\nvertex 1 0 0\nendloop\n", head);
    expect_bad(buf, "c.stl", PD_ERR_PARSE, "c.stl:6: expected 'vertex', found 'endloop'");
    snprintf(buf, sizeof buf,
             "%svertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n", head);
    expect_bad(buf, "d.stl", PD_ERR_PARSE, "d.stl:8: expected 'facet' or 'endsolid', found end of file");
    snprintf(buf, sizeof buf,
             "%svertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\nrubbish\n", head);
    expect_bad(buf, "e.stl", PD_ERR_PARSE, "e.stl:10: expected 'solid' or end of file, found 'rubbish'");
    expect_bad("solid empty\nendsolid empty\n", "f.stl", PD_ERR_PARSE, "no faces");
}

/* A binary STL in memory; the header starts with "solid" as some exporters
 * write it, which must not make the reader take it for ASCII. */
static unsigned char *binary_stl(const float (*tri)[9], uint32_t n, uint32_t declared, size_t *size)
{
    *size = 84 + 50 * (size_t)n;
    unsigned char *b = calloc(1, *size);
    memset(b, ' ', 80);
    memcpy(b, "solid exported by a tool that writes ASCII words", 48);
    for (int i = 0; i < 4; i++)
        b[80 + i] = (unsigned char)(declared >> (8 * i));
    for (uint32_t t = 0; t < n; t++) {
        unsigned char *r = b + 84 + 50 * t + 12;
        for (int k = 0; k < 9; k++) {
            uint32_t u;
            memcpy(&u, &tri[t][k], 4);
            for (int i = 0; i < 4; i++)
                r[4 * k + i] = (unsigned char)(u >> (8 * i));
        }
    }
    return b;
}

static const float tetra_tris[4][9] = {
    {0, 0, 0, 0, 1, 0, 1, 0, 0},
    {0, 0, 0, 1, 0, 0, 0, 0, 1},
    {0, 0, 0, 0, 0, 1, 0, 1, 0},
    {1, 0, 0, 0, 1, 0, 0, 0, 0.25f},
};

static void test_stl_binary(void)
{
    size_t size;
    unsigned char *b = binary_stl(tetra_tris, 4, 4, &size);
    pd_mesh *m = NULL;
    pd_diag d;
    pd_diag_init(&d);
    /* Told apart from ASCII by content, without help from the name. */
    CHECK_STATUS(pd_mesh_parse(b, size, "noext", NULL, &m, &d), PD_OK);
    if (m) {
        /* Corners (1,0,0), (0,1,0) repeat bit-identically; (0,0,1) and
         * (0,0,0.25) differ: 5 vertices. */
        CHECK_INT(m->nverts, 5);
        CHECK_INT(m->ntris, 4);
        CHECK(tri_is(m, 0, 0, 1, 2) && tri_is(m, 1, 0, 2, 3) && tri_is(m, 3, 2, 1, 4));
        CHECK_NEAR(m->verts[4].z, 0.25, 0.0, "exact: 0.25 is a float");
        pd_mesh_free(m);
        m = NULL;
    }
    /* Units: millimetres are 1e-3 m, applied by one multiplication. */
    pd_mesh_read_options o;
    pd_mesh_read_options_default(&o);
    o.units = PD_UNITS_MM;
    CHECK_STATUS(pd_mesh_parse(b, size, "tetra.stl", &o, &m, &d), PD_OK);
    if (m) {
        CHECK_NEAR(m->verts[4].z, 0.25 * 0.001, 0.0, "exact: same multiplication");
        pd_mesh_free(m);
        m = NULL;
    }

    /* Truncated: the size does not hold the declared triangles. */
    pd_mesh sentinel_mesh = {0};
    m = &sentinel_mesh;
    CHECK_STATUS(pd_mesh_parse(b, size - 1, "cut.stl", NULL, &m, &d), PD_ERR_PARSE);
    CHECK(strstr(d.message, "cut.stl") && strstr(d.message, "4 triangles"));
    CHECK(m == &sentinel_mesh);
    /* A lying count is refused before allocating. */
    free(b);
    b = binary_stl(tetra_tris, 4, 2000000000u, &size);
    CHECK_STATUS(pd_mesh_parse(b, size, "liar.stl", NULL, &m, &d), PD_ERR_RANGE);
    CHECK(strstr(d.message, "liar.stl") && strstr(d.message, "2000000000"));
    free(b);
    b = binary_stl(tetra_tris, 4, 5000000u, &size);
    CHECK_STATUS(pd_mesh_parse(b, size, "liar2.stl", NULL, &m, &d), PD_ERR_PARSE);
    CHECK(strstr(d.message, "5000000 triangles") != NULL);
    free(b);
    /* A NaN corner names its triangle. */
    float bad[4][9];
    memcpy(bad, tetra_tris, sizeof bad);
    bad[1][4] = NAN;
    b = binary_stl((const float (*)[9])bad, 4, 4, &size);
    CHECK_STATUS(pd_mesh_parse(b, size, "nan.stl", NULL, &m, &d), PD_ERR_NONFINITE);
    CHECK(strstr(d.message, "nan.stl: triangle 2") != NULL);
    free(b);
    CHECK(m == &sentinel_mesh);
    /* Too short for a header. */
    m = &sentinel_mesh;
    CHECK_STATUS(pd_mesh_parse("\x01\x00\x02", 3, "tiny.stl", NULL, &m, &d), PD_ERR_PARSE);
    CHECK(strstr(d.message, "tiny.stl") != NULL);
}

/* --- OBJ ------------------------------------------------------------------- */

static void test_obj(void)
{
    pd_mesh *m = parse_ok("# cube corner\n"
                          "mtllib a.mtl\n"
                          "o thing\n"
                          "v 0 0 0\n"
                          "v 1.5 0 0 1.0\n" /* w ignored */
                          "v 0 1 0 0.5 0.5 0.5\n"
                          "vt 0 0\nvt 1 0\nvt 0 1\n"
                          "vn 0 0 1\n"
                          "g side\ns off\nusemtl red\n"
                          "f 1 3 2\n"
                          "f 1/1 2/2 3/3  # trailing comment\n"
                          "f 1/1/1 2/2/1 3/3/1\n"
                          "f 1//1 2//1 3//1\n"
                          "v 0 0 -2\n"
                          "f -4 -3 -1\n"     /* relative: 1 2 4 */
                          "f 1 2 \\\n 3 4\n" /* continued line: a quad */
                          "l 1 2\n",
                          "thing.obj");
    if (m) {
        CHECK_INT(m->nverts, 4);
        CHECK_INT(m->ntris, 7);
        CHECK_NEAR(m->verts[1].x, 1.5, 0.0, exact);
        CHECK_NEAR(m->verts[3].z, -2.0, 0.0, exact);
        CHECK(tri_is(m, 0, 0, 2, 1) && tri_is(m, 1, 0, 1, 2) && tri_is(m, 3, 0, 1, 2));
        CHECK(tri_is(m, 4, 0, 1, 3));
        CHECK(tri_is(m, 5, 0, 1, 2) && tri_is(m, 6, 0, 2, 3));
        pd_mesh_free(m);
    }
    /* A hexagon fans into 4 triangles. */
    m = parse_ok("v 1 0 0\nv 2 0 0\nv 3 1 0\nv 2 2 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5 6\n", "hex.obj");
    if (m) {
        CHECK_INT(m->ntris, 4);
        CHECK(tri_is(m, 3, 0, 4, 5));
        pd_mesh_free(m);
    }

    const char *v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
    char buf[256];
    snprintf(buf, sizeof buf, "%sf 1 2 0\n", v3);
    expect_bad(buf, "a.obj", PD_ERR_RANGE, "a.obj:4: vertex index 0");
    snprintf(buf, sizeof buf, "%sf 1 2 4\n", v3);
    expect_bad(buf, "b.obj", PD_ERR_RANGE, "b.obj:4: vertex index 4 out of range");
    snprintf(buf, sizeof buf, "%sf -1 -2 -4\n", v3);
    expect_bad(buf, "c.obj", PD_ERR_RANGE, "c.obj:4: relative vertex index -4");
    snprintf(buf, sizeof buf, "%sf 1 2\n", v3);
    expect_bad(buf, "d.obj", PD_ERR_PARSE, "d.obj:4: face with 2 vertices");
    snprintf(buf, sizeof buf, "%sf 1/x 2 3\n", v3);
    expect_bad(buf, "e.obj", PD_ERR_PARSE, "e.obj:4: expected a face corner");
    snprintf(buf, sizeof buf, "%sf 1/2/3/4 2 3\n", v3);
    expect_bad(buf, "e2.obj", PD_ERR_PARSE, "e2.obj:4: expected a face corner");
    snprintf(buf, sizeof buf, "%sf one 2 3\n", v3);
    expect_bad(buf, "f.obj", PD_ERR_PARSE, "f.obj:4: expected a vertex index, found 'one'");
    expect_bad("v 0 0 0\nv 1 y 0\n", "g.obj", PD_ERR_PARSE, "g.obj:2: expected a y coordinate, found 'y'");
    expect_bad("v 0 0 0\nv 1 0\n", "h.obj", PD_ERR_PARSE, "h.obj:2: expected a z coordinate, found end of line");
    expect_bad("v 0 0 0\nv 1 0 NaN\n", "i.obj", PD_ERR_NONFINITE, "i.obj:2:");
    snprintf(buf, sizeof buf, "%sf 1 2 3\n0.5 0.5 0.5\n", v3);
    expect_bad(buf, "j.obj", PD_ERR_PARSE, "j.obj:5: expected an OBJ keyword, found '0.5'");
    expect_bad("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "k.obj", PD_ERR_PARSE, "no faces");
    /* Some exporter's own keyword is skipped, not fatal. */
    snprintf(buf, sizeof buf, "%smyext 1 2\nf 1 2 3\n", v3);
    m = parse_ok(buf, "ext.obj");
    pd_mesh_free(m);
}

/* Extra tokens on a vertex line (OFF's colour, OBJ's w) follow one rule in
 * both readers: numbers, taken and ignored; anything else ('abc', 'nan',
 * '1e999') refused with the same status and message, naming the line. */
static void test_vertex_rest(void)
{
    static const char *const bad[] = {"abc", "nan", "1e999", "-inf", "0x"};
    static const pd_status want[] = {PD_ERR_PARSE, PD_ERR_NONFINITE, PD_ERR_NONFINITE,
                                     PD_ERR_NONFINITE, PD_ERR_PARSE};
    for (int i = 0; i < 6; i++) {
        const char *tok = i < 5 ? bad[i] : "0.5 1 0.25 1"; /* a colour: accepted */
        char off[256], obj[256];
        snprintf(off, sizeof off, "OFF\n4 4 0\n0 0 0\n1 0 0 %s\n0 1 0\n0 0 1\n"
                 "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n", tok);
        snprintf(obj, sizeof obj, "v 0 0 0\nv 1 0 0 %s\nv 0 1 0\nv 0 0 1\n"
                 "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n", tok);
        pd_mesh *mo = NULL, *mj = NULL;
        pd_diag dof, dobj;
        pd_status so = parse_as(off, "v.off", PD_FORMAT_AUTO, PD_UNITS_M, &mo, &dof);
        pd_status sj = parse_as(obj, "v.obj", PD_FORMAT_AUTO, PD_UNITS_M, &mj, &dobj);
        CHECK_STATUS(so, i < 5 ? want[i] : PD_OK);
        CHECK_STATUS(sj, i < 5 ? want[i] : PD_OK);
        if (i < 5) {
            /* The same words after "v.off:4: " and "v.obj:2: ". */
            const char *mo_text = strstr(dof.message, ": "), *mj_text = strstr(dobj.message, ": ");
            CHECK(strncmp(dof.message, "v.off:4: ", 9) == 0 &&
                  strncmp(dobj.message, "v.obj:2: ", 9) == 0);
            CHECK(mo_text && mj_text && strcmp(mo_text, mj_text) == 0);
            CHECK(strstr(dof.message, tok) != NULL);
            if (!mo_text || !mj_text || strcmp(mo_text, mj_text) != 0)
                printf("     %s\n     %s\n", dof.message, dobj.message);
        } else {
            CHECK(mo && mj && mo->nverts == 4 && mj->nverts == 4);
        }
        pd_mesh_free(mo);
        pd_mesh_free(mj);
    }
}

/* --- format, units, files ---------------------------------------------------- */

static void test_format(void)
{
    pd_mesh *m = NULL;
    pd_diag d;
    /* Content decides over the name... */
    m = parse_ok(tetra_off, "misnamed.stl");
    CHECK(m && m->ntris == 4);
    pd_mesh_free(m);
    m = parse_ok("\xEF\xBB\xBF# only a comment first\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "noext");
    CHECK(m && m->ntris == 1);
    pd_mesh_free(m);
    /* ...the name breaks ties when content says nothing... */
    expect_bad("# nothing but comments\n", "x.obj", PD_ERR_PARSE, "x.obj: no faces");
    expect_bad("# nothing but comments\n", "x.OFF", PD_ERR_PARSE, "x.OFF: expected OFF header");
    /* ...and an explicit format is obeyed. */
    expect_bad_as(tetra_off, "tetra.off", PD_FORMAT_OBJ, PD_ERR_PARSE, "tetra.off:4: expected an OBJ keyword");
    /* Neither ASCII STL nor binary: said so, and what it looks like, never
     * bytes of text read as a triangle count. */
    expect_bad_as(tetra_off, "tetra.off", PD_FORMAT_STL, PD_ERR_FORMAT,
                  "tetra.off: does not look like binary STL (162 bytes of text, not 84 plus 50 per "
                  "triangle) nor like ASCII STL (no 'solid' line first): it looks like OFF");
    CHECK_STATUS(parse_as(tetra_off, "x.txt", PD_FORMAT_OFF, PD_UNITS_M, &m, &d), PD_OK);
    pd_mesh_free(m);
    /* Unrecognisable. */
    expect_bad("hello world\n", "x.txt", PD_ERR_FORMAT, "x.txt");
    expect_bad("", "empty", PD_ERR_FORMAT, "empty");
}

static void test_units(void)
{
    CHECK_NEAR(pd_units_scale(PD_UNITS_M), 1.0, 0.0, "definition");
    CHECK_NEAR(pd_units_scale(PD_UNITS_CM), 0.01, 0.0, "definition");
    CHECK_NEAR(pd_units_scale(PD_UNITS_MM), 0.001, 0.0, "definition");
    CHECK_NEAR(pd_units_scale(PD_UNITS_IN), 0.0254, 0.0, "definition of the inch");
    pd_units u = PD_UNITS_M;
    CHECK_STATUS(pd_units_parse("mm", &u), PD_OK);
    CHECK_INT(u, PD_UNITS_MM);
    CHECK_STATUS(pd_units_parse("in", &u), PD_OK);
    CHECK_INT(u, PD_UNITS_IN);
    CHECK_STATUS(pd_units_parse("cm", &u), PD_OK);
    CHECK_INT(u, PD_UNITS_CM);
    CHECK_STATUS(pd_units_parse("m", &u), PD_OK);
    CHECK_INT(u, PD_UNITS_M);
    CHECK_STATUS(pd_units_parse("furlong", &u), PD_ERR_USAGE);
    CHECK_STATUS(pd_units_parse("MM", &u), PD_ERR_USAGE);

    /* Every coordinate read in mm is the metre reading times 1e-3, exactly:
     * one multiplication by pd_units_scale. */
    pd_mesh *m = NULL, *mm = NULL;
    pd_diag d;
    CHECK_STATUS(parse_as(tetra_off, "t.off", PD_FORMAT_AUTO, PD_UNITS_M, &m, &d), PD_OK);
    CHECK_STATUS(parse_as(tetra_off, "t.off", PD_FORMAT_AUTO, PD_UNITS_MM, &mm, &d), PD_OK);
    if (m && mm) {
        int same = 1;
        for (int i = 0; i < m->nverts; i++)
            same &= mm->verts[i].x == m->verts[i].x * 0.001 && mm->verts[i].y == m->verts[i].y * 0.001 &&
                    mm->verts[i].z == m->verts[i].z * 0.001;
        CHECK(same);
        CHECK_NEAR(mm->verts[1].x, 1.5 * 0.001, 0.0, "exact: same multiplication");
    }
    pd_mesh_free(m);
    pd_mesh_free(mm);
}

static void test_files(void)
{
    char path[] = "/tmp/pd_test_mesh_XXXXXX";
    int fd = mkstemp(path);
    CHECK(fd >= 0);
    if (fd < 0)
        return;
    FILE *f = fdopen(fd, "wb");
    fputs(tetra_off, f);
    fclose(f);
    pd_mesh *m = NULL;
    pd_diag d;
    pd_diag_init(&d);
    pd_mesh_read_options o;
    pd_mesh_read_options_default(&o);
    o.format = PD_FORMAT_OFF; /* the temp name has no extension */
    CHECK_STATUS(pd_mesh_read(path, &o, &m, &d), PD_OK);
    if (m) {
        CHECK_INT(m->ntris, 4);
        CHECK_NEAR(m->verts[2].y, 2.25, 0.0, exact);
        pd_mesh_free(m);
    }
    remove(path);
    m = NULL;
    CHECK_STATUS(pd_mesh_read("/nonexistent/part.off", NULL, &m, &d), PD_ERR_IO);
    CHECK(strstr(d.message, "/nonexistent/part.off") != NULL);
    CHECK(m == NULL);
    /* A directory opens but cannot be read as a file. */
    CHECK_STATUS(pd_mesh_read("/tmp", NULL, &m, &d), PD_ERR_IO);
    CHECK(m == NULL);
}

/* --- every prefix ------------------------------------------------------------ */

/* Each prefix of a valid file, in a buffer of exactly that size (so the
 * sanitizer sees any read past it), must parse or fail with an input error
 * and a message; never crash or hang. */
static void all_prefixes(const void *data, size_t size, const char *name, pd_mesh_format format)
{
    int clean = 1, full_ok = 0;
    for (size_t n = 0; n <= size; n++) {
        unsigned char *copy = malloc(n ? n : 1);
        memcpy(copy, data, n);
        pd_mesh_read_options o;
        pd_mesh_read_options_default(&o);
        for (int pass = 0; pass < 2; pass++) {
            o.format = pass ? format : PD_FORMAT_AUTO;
            pd_mesh *m = NULL;
            pd_diag d;
            pd_diag_init(&d);
            pd_status st = pd_mesh_parse(copy, n, name, &o, &m, &d);
            if (st == PD_OK) {
                clean &= m != NULL && m->ntris > 0;
                if (n == size)
                    full_ok++;
                pd_mesh_free(m);
            } else {
                clean &= m == NULL && pd_status_is_input_error(st) && d.message[0] != '\0';
            }
        }
        free(copy);
    }
    CHECK(clean);
    CHECK_INT(full_ok, 2);
}

static void test_prefixes(void)
{
    all_prefixes(tetra_off, strlen(tetra_off), "p.off", PD_FORMAT_OFF);
    all_prefixes(tetra_stl, strlen(tetra_stl), "p.stl", PD_FORMAT_STL);
    static const char obj[] = "# c\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvt 0 0\n"
                              "f 1/1 3/1 2/1\nf 1//1 2//1 4//1\nf -4 -1 -2 \\\n\nf 2 3 4\n";
    all_prefixes(obj, strlen(obj), "p.obj", PD_FORMAT_OBJ);
    size_t size;
    unsigned char *b = binary_stl(tetra_tris, 4, 4, &size);
    all_prefixes(b, size, "p.stl", PD_FORMAT_STL);
    free(b);
}

/* --- weld, clone, size ---------------------------------------------------------- */

static pd_mesh *make_mesh(const pd_vec3 *v, int nv, const int (*t)[3], int nt)
{
    pd_mesh *m = malloc(sizeof *m);
    m->nverts = nv;
    m->ntris = nt;
    m->verts = malloc(sizeof *m->verts * (size_t)nv);
    m->tris = malloc(sizeof *m->tris * (size_t)(nt ? nt : 1));
    memcpy(m->verts, v, sizeof *m->verts * (size_t)nv);
    memcpy(m->tris, t, sizeof *m->tris * (size_t)nt);
    return m;
}

static void test_weld(void)
{
    const double tol = 1e-6;
    /* Two triangles of a square given as a soup (6 corners) plus copies at
     * 0.5 tol (merged) and 2 tol (kept), a -0.0 copy (bit-identical to 0)
     * and an unused vertex. */
    const pd_vec3 v[] = {
        {0, 0, 0}, {1, 0, 0}, {1, 1, 0},          /* 0 1 2 */
        {-0.0, 0, 0}, {1, 1, 0}, {0, 1, 0},       /* 3 = 0, 4 = 2, 5 */
        {1 + 0.5 * tol, 0, 0}, {0, 1, 2 * tol},   /* 6 ~ 1, 7 kept */
        {5, 5, 5},                                /* 8 unused */
        {0, 1 + 0.5 * tol, 0},                    /* 9 ~ 5 */
    };
    const int t[][3] = {{0, 1, 2}, {3, 4, 5}, {6, 2, 7}, {5, 9, 2}};
    pd_mesh *m = make_mesh(v, 10, t, 4);
    int merged = -1;
    CHECK_STATUS(pd_mesh_weld(m, tol, &merged), PD_OK);
    /* Survivors: 0 1 2 5 7 (in that order); 3 4 6 9 merged, 8 dropped. */
    CHECK_INT(m->nverts, 5);
    CHECK_INT(merged, 5);
    /* Triangle {5, 9, 2} collapsed (9 is 5) and is gone. */
    CHECK_INT(m->ntris, 3);
    CHECK(tri_is(m, 0, 0, 1, 2) && tri_is(m, 1, 0, 2, 3) && tri_is(m, 2, 1, 2, 4));
    /* The survivor of a cluster is its first vertex, bit for bit. */
    CHECK_NEAR(m->verts[1].x, 1.0, 0.0, "exact: first vertex survives");
    CHECK_NEAR(m->verts[3].y, 1.0, 0.0, "exact: first vertex survives");
    CHECK_NEAR(m->verts[4].z, 2 * tol, 0.0, "exact: vertex kept as is");
    pd_mesh_free(m);

    /* Order decides the survivor: the same cluster listed the other way round. */
    const pd_vec3 w[] = {{0.4e-6, 0, 0}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const int wt[][3] = {{1, 2, 3}, {0, 2, 3}};
    m = make_mesh(w, 4, wt, 2);
    CHECK_STATUS(pd_mesh_weld(m, tol, NULL), PD_OK);
    CHECK_INT(m->nverts, 3);
    CHECK_INT(m->ntris, 2);
    CHECK_NEAR(m->verts[0].x, 0.4e-6, 0.0, "exact: first in order survives");
    pd_mesh_free(m);

    /* tol 0: only bit-identical vertices merge (and -0 with 0). */
    m = make_mesh(v, 10, t, 4);
    CHECK_STATUS(pd_mesh_weld(m, 0.0, &merged), PD_OK);
    CHECK_INT(m->nverts, 7); /* 0 1 2 5 6 7 9: 3 and 4 merged, 8 dropped */
    CHECK_INT(merged, 3);
    CHECK_INT(m->ntris, 4);
    pd_mesh_free(m);

    /* Coordinates too large for grid cells of this size: exact merging only,
     * and no overflow. */
    const pd_vec3 big[] = {{1e300, 0, 0}, {0, 1e300, 0}, {0, 0, 1e300}, {1e300, 0, 0}};
    const int bt[][3] = {{0, 1, 2}, {3, 2, 1}};
    m = make_mesh(big, 4, bt, 2);
    CHECK_STATUS(pd_mesh_weld(m, tol, &merged), PD_OK);
    CHECK_INT(m->nverts, 3);
    CHECK_INT(m->ntris, 2);
    pd_mesh_free(m);

    /* Against brute force: clusters of points jittered by 0.05 to 1 tol
     * (seeded). Each triangle (i, A, B) joins point i to two far anchors, so
     * none collapses and the corner of triangle i shows i's survivor, which
     * must be the first earlier survivor within tol, as an O(n^2) scan says. */
    {
        enum { NP = 600 };
        test_rng g = {7};
        pd_vec3 *p = malloc(sizeof *p * (NP + 2));
        int (*pt)[3] = malloc(sizeof *pt * NP);
        int *ref = malloc(sizeof *ref * (NP + 2));
        p[0] = (pd_vec3){100, 0, 0};
        p[1] = (pd_vec3){0, 100, 0};
        for (int i = 2; i < NP + 2; i++) {
            pd_vec3 c = {(double)(rng_next(&g) % 8) * 0.01, (double)(rng_next(&g) % 8) * 0.01, 0.5};
            pd_vec3 u = rng_unit_vector(&g);
            double s = tol * rng_range(&g, 0.05, 1.0);
            p[i] = (pd_vec3){c.x + s * u.x, c.y + s * u.y, c.z + s * u.z};
            pt[i - 2][0] = i;
            pt[i - 2][1] = 0;
            pt[i - 2][2] = 1;
        }
        for (int i = 0; i < NP + 2; i++) {
            ref[i] = i;
            for (int r = 0; r < i; r++) {
                pd_vec3 dv = {p[i].x - p[r].x, p[i].y - p[r].y, p[i].z - p[r].z};
                if (ref[r] == r && sqrt(dv.x * dv.x + dv.y * dv.y + dv.z * dv.z) <= tol) {
                    ref[i] = r;
                    break;
                }
            }
        }
        int nrep = 0;
        for (int i = 0; i < NP + 2; i++)
            nrep += ref[i] == i;
        m = make_mesh(p, NP + 2, (const int (*)[3])pt, NP);
        CHECK_STATUS(pd_mesh_weld(m, tol, &merged), PD_OK);
        CHECK_INT(m->nverts, nrep);
        CHECK(nrep > 66 && nrep < NP / 2); /* the test does merge, and not everything */
        if (!(nrep > 66 && nrep < NP / 2))
            printf("     nrep %d\n", nrep);
        int agree = m->ntris == NP;
        for (int t2 = 0; agree && t2 < NP; t2++) {
            pd_vec3 got = m->verts[m->tris[t2][0]], want = p[ref[t2 + 2]];
            agree = got.x == want.x && got.y == want.y && got.z == want.z;
        }
        CHECK(agree);
        pd_mesh_free(m);
        free(p);
        free(pt);
        free(ref);
    }

    /* A jittered soup of a closed box welds back to the box: every corner
     * copy moved by up to 0.1 tol (a random direction, seeded). */
    test_rng r = {42};
    pd_mesh *box = mesh_box(2, 1, 0.5);
    if (box) {
        int nt = box->ntris;
        pd_vec3 *sv = malloc(sizeof *sv * (size_t)(3 * nt));
        int (*st)[3] = malloc(sizeof *st * (size_t)nt);
        for (int i = 0; i < nt; i++)
            for (int k = 0; k < 3; k++) {
                pd_vec3 p = box->verts[box->tris[i][k]], u = rng_unit_vector(&r);
                double s = 0.1 * tol * rng_uniform(&r);
                sv[3 * i + k] = (pd_vec3){p.x + s * u.x, p.y + s * u.y, p.z + s * u.z};
                st[i][k] = 3 * i + k;
            }
        m = make_mesh(sv, 3 * nt, (const int (*)[3])st, nt);
        CHECK_STATUS(pd_mesh_weld(m, tol * pd_mesh_size(box), &merged), PD_OK);
        CHECK_INT(m->nverts, box->nverts);
        CHECK_INT(m->ntris, nt);
        CHECK_INT(merged, 3 * nt - box->nverts);
        pd_mesh_free(m);
        free(sv);
        free(st);
        pd_mesh_free(box);
    }
}

static void test_clone_size(void)
{
    pd_mesh *box = mesh_box(3, 4, 12);
    CHECK(box != NULL);
    if (!box)
        return;
    CHECK_REL(pd_mesh_size(box), 13.0, 1e-15, "round-off of one sqrt: 3-4-12 box has diagonal 13");
    pd_mesh *c = pd_mesh_clone(box);
    CHECK(c != NULL);
    if (c) {
        CHECK(c->verts != box->verts && c->tris != box->tris);
        CHECK_INT(c->nverts, box->nverts);
        CHECK_INT(c->ntris, box->ntris);
        CHECK(memcmp(c->verts, box->verts, sizeof *c->verts * (size_t)c->nverts) == 0);
        CHECK(memcmp(c->tris, box->tris, sizeof *c->tris * (size_t)c->ntris) == 0);
        /* Deep: changing the copy leaves the original alone. */
        c->verts[0].x += 100.0;
        c->tris[0][0] = c->tris[0][1];
        CHECK(box->verts[0].x != c->verts[0].x && box->tris[0][0] != c->tris[0][0]);
        pd_mesh_free(c);
    }
    pd_mesh_free(box);
    CHECK_NEAR(pd_mesh_size(NULL), 0.0, 0.0, "definition: no vertices");
}

/* Exact reference for two triangles of small integer coordinates (every
 * product below is an integer far under 2^53): their relative interiors
 * cross when each has vertices strictly on both sides of the other's plane
 * and the open chords the two cut from the planes' common line overlap.
 * Positions along that line are fractions num / den, den > 0, compared by
 * cross-multiplication. Written apart from the library's formulation (which
 * compares the chords by two orientation signs). */
typedef long long ll;
static ll det3(const ll a[3], const ll b[3], const ll c[3], const ll d[3])
{
    ll u[3], v[3], w[3];
    for (int k = 0; k < 3; k++) {
        u[k] = b[k] - a[k];
        v[k] = c[k] - a[k];
        w[k] = d[k] - a[k];
    }
    return u[0] * (v[1] * w[2] - v[2] * w[1]) + u[1] * (v[2] * w[0] - v[0] * w[2]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
}

static void normal_of(ll t[3][3], ll n[3])
{
    ll u[3], v[3];
    for (int k = 0; k < 3; k++) {
        u[k] = t[1][k] - t[0][k];
        v[k] = t[2][k] - t[0][k];
    }
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
}

static int shared_corners(const int a[3], const int b[3])
{
    int n = 0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            n += a[i] == b[j];
    return n;
}

static ll dotl(const ll a[3], const ll b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* The chord of t on the plane of o: its two ends along dir, lo <= hi. */
static void chord(ll t[3][3], ll o[3][3], const ll dir[3], ll num[2], ll den[2])
{
    int n = 0;
    for (int a = 0; a < 3 && n < 2; a++) {
        int b = (a + 1) % 3;
        ll da = det3(o[0], o[1], o[2], t[a]), db = det3(o[0], o[1], o[2], t[b]);
        if (da == 0) {
            num[n] = dotl(dir, t[a]);
            den[n++] = 1;
        } else if ((da > 0 && db < 0) || (da < 0 && db > 0)) {
            ll e[3] = {t[b][0] - t[a][0], t[b][1] - t[a][1], t[b][2] - t[a][2]};
            ll dd = da - db, sg = dd < 0 ? -1 : 1;
            num[n] = sg * (dotl(dir, t[a]) * dd + da * dotl(dir, e));
            den[n++] = sg * dd;
        }
    }
    if (num[0] * den[1] > num[1] * den[0]) {
        ll x = num[0], y = den[0];
        num[0] = num[1];
        den[0] = den[1];
        num[1] = x;
        den[1] = y;
    }
}

static int straddles(ll t[3][3], ll o[3][3])
{
    int pos = 0, neg = 0;
    for (int i = 0; i < 3; i++) {
        ll d = det3(o[0], o[1], o[2], t[i]);
        pos |= d > 0;
        neg |= d < 0;
    }
    return pos && neg;
}

static int cross_ref(ll p[3][3], ll q[3][3])
{
    if (!straddles(p, q) || !straddles(q, p))
        return 0;
    ll np[3], nq[3], dir[3], pn[2], pd[2], qn[2], qd[2];
    normal_of(p, np);
    normal_of(q, nq);
    dir[0] = np[1] * nq[2] - np[2] * nq[1];
    dir[1] = np[2] * nq[0] - np[0] * nq[2];
    dir[2] = np[0] * nq[1] - np[1] * nq[0];
    chord(p, q, dir, pn, pd);
    chord(q, p, dir, qn, qd);
    /* max(lo) < min(hi): each chord starts before the other ends. */
    return pn[0] * qd[1] < qn[1] * pd[0] && qn[0] * pd[1] < pn[1] * qd[0];
}

/* Triangles a and b of a mesh of integer corners c, by the reference. */
static int cross_ref_tris(ll (*c)[3], int (*tri)[3], int a, int b)
{
    ll p[3][3], q[3][3];
    for (int i = 0; i < 3; i++)
        for (int k = 0; k < 3; k++) {
            p[i][k] = c[tri[a][i]][k];
            q[i][k] = c[tri[b][i]][k];
        }
    return cross_ref(p, q);
}

/* pd_mesh_self_crossing on a mesh of integer corners c against every pair's
 * reference (pairs sharing an edge never cross): 1 when it finds a crossing
 * exactly when some pair crosses and the pair it names does; *any says
 * whether one does. */
static int agrees_with_ref(ll (*c)[3], pd_vec3 *v, int nv, int (*tri)[3], int nt, int *any)
{
    *any = 0;
    for (int a = 0; a < nt && !*any; a++)
        for (int b = a + 1; b < nt && !*any; b++)
            *any = shared_corners(tri[a], tri[b]) < 2 && cross_ref_tris(c, tri, a, b);
    pd_mesh m = {nv, v, nt, tri};
    int ta, tb;
    pd_vec3 at;
    if (pd_mesh_self_crossing(&m, NULL, &ta, &tb, &at, NULL) != PD_OK || (ta >= 0) != *any)
        return 0;
    return ta < 0 || (ta < tb && cross_ref_tris(c, tri, ta, tb));
}

/* pd_mesh_self_crossing on two triangles against the reference, over random
 * small integer triangles (degenerate contacts are frequent: vertices on
 * the other's plane, on its edges, shared vertices and edges), and on a
 * mesh of many such triangles against every pair's reference. */
static void test_self_crossing(void)
{
    test_rng rng = {20261127};
    int agree = 0, crossings = 0, trials = 20000;
    for (int it = 0; it < trials; it++) {
        int R = 1 + (int)(rng_uniform(&rng) * 3.0);
        ll c[6][3];
        for (int i = 0; i < 6; i++)
            for (int k = 0; k < 3; k++)
                c[i][k] = (ll)(rng_uniform(&rng) * (2 * R + 1)) - R;
        int tri[2][3] = {{0, 1, 2}, {3, 4, 5}};
        double u = rng_uniform(&rng);
        if (u < 0.3)
            tri[1][0] = 0; /* a shared vertex */
        if (u < 0.05)
            tri[1][1] = 1; /* and a shared edge */
        ll p[3][3], q[3][3];
        for (int i = 0; i < 3; i++)
            for (int k = 0; k < 3; k++) {
                p[i][k] = c[tri[0][i]][k];
                q[i][k] = c[tri[1][i]][k];
            }
        pd_vec3 v[6];
        for (int i = 0; i < 6; i++)
            v[i] = v3((double)c[i][0], (double)c[i][1], (double)c[i][2]);
        pd_mesh m = {6, v, 2, tri};
        int ta, tb;
        pd_vec3 at;
        pd_status st = pd_mesh_self_crossing(&m, NULL, &ta, &tb, &at, NULL);
        int want = cross_ref(p, q);
        crossings += want;
        agree += st == PD_OK && (ta >= 0) == want;
        if ((ta >= 0) != want && trials - agree < 4)
            printf("     triangles (%g %g %g)(%g %g %g)(%g %g %g) and (%g %g %g)(%g %g %g)(%g %g "
                   "%g): reference %d\n", v[tri[0][0]].x, v[tri[0][0]].y, v[tri[0][0]].z,
                   v[tri[0][1]].x, v[tri[0][1]].y, v[tri[0][1]].z, v[tri[0][2]].x,
                   v[tri[0][2]].y, v[tri[0][2]].z, v[tri[1][0]].x, v[tri[1][0]].y,
                   v[tri[1][0]].z, v[tri[1][1]].x, v[tri[1][1]].y, v[tri[1][1]].z,
                   v[tri[1][2]].x, v[tri[1][2]].y, v[tri[1][2]].z, want);
    }
    CHECK_INT(agree, trials);
    /* Both answers occur often enough for the comparison to mean something. */
    CHECK(crossings > trials / 20 && crossings < trials - trials / 20);

    /* Many triangles: the sweep finds a crossing exactly when some pair
     * crosses, and the pair it names does. */
    for (int it = 0; it < 200; it++) {
        enum { NV = 12, NT = 6 };
        pd_vec3 v[NV];
        ll c[NV][3];
        int tri[NT][3];
        for (int i = 0; i < NV; i++) {
            for (int k = 0; k < 3; k++)
                c[i][k] = (ll)(rng_uniform(&rng) * 9.0) - 4;
            v[i] = v3((double)c[i][0], (double)c[i][1], (double)c[i][2]);
        }
        for (int t = 0; t < NT; t++)
            for (int k = 0; k < 3; k++)
                tri[t][k] = (int)(rng_uniform(&rng) * NV);
        int any;
        CHECK(agrees_with_ref(c, v, NV, tri, NT, &any));
    }
}

/* Meshes of small triangles on a random walk of integer points (corners
 * and edges shared often, points repeated under other indices): the search
 * finds a crossing exactly when the brute-force reference finds one, and
 * the pair it names crosses. Larger than the meshes above, so that the tree
 * of boxes has levels above its leaves. */
/* Random walks of nv vertices in steps of [-2, 2], with nt triangles on
 * nearby indices (small against the whole, many pairs far apart), each
 * mesh's answer against the reference; *found counts the meshes that
 * cross. Returns how many of cases agreed. */
static int walk_cases(test_rng *rng, int nv, int nt, int cases, int *found)
{
    enum { NV_MAX = 300, NT_MAX = 30 };
    static pd_vec3 v[NV_MAX];
    static ll c[NV_MAX][3];
    static int tri[NT_MAX][3];
    int agree = 0;
    *found = 0;
    for (int it = 0; it < cases; it++) {
        for (int i = 0; i < nv; i++) {
            for (int k = 0; k < 3; k++)
                c[i][k] = (i ? c[i - 1][k] : 0) + (ll)(rng_uniform(rng) * 5.0) - 2;
            v[i] = v3((double)c[i][0], (double)c[i][1], (double)c[i][2]);
        }
        for (int t = 0; t < nt; t++) {
            int base = (int)(rng_uniform(rng) * nv);
            for (int k = 0; k < 3; k++)
                tri[t][k] = k == 0 ? base : (base + 1 + (int)(rng_uniform(rng) * 4)) % nv;
        }
        int any;
        agree += agrees_with_ref(c, v, nv, tri, nt, &any);
        *found += any;
    }
    return agree;
}

static void test_self_crossing_many(void)
{
    test_rng rng = {20261128};
    int found, cases = 1000;
    CHECK_INT(walk_cases(&rng, 40, 12, cases, &found), cases);
    /* Both answers occur. */
    pd_note("self-crossing, %d of %d meshes of 12 triangles on 40 vertices cross\n", found, cases);
    CHECK(found > 0 && found < cases);

    /* Larger walks, whose tree has levels of oriented boxes above its
     * leaves of 8, many of them about degenerate triangles (repeated
     * corners: a frame along an edge with no plane). */
    cases = 300;
    CHECK_INT(walk_cases(&rng, 300, 30, cases, &found), cases);
    pd_note("self-crossing, %d of %d meshes of 30 triangles on 300 vertices cross\n", found,
            cases);
    CHECK(found > 0 && found < cases);
}

/* A rod of the given number of sides, radius 0.05 and length 1, capped by
 * fans about one corner, turned off the axes (about (1, 2, 3) by 0.7 rad);
 * shifted by dx across its axis. Its 2 (2 n - 2) triangles are written from
 * t0 on, its 2 n vertices from v0 on. */
static void turned_rod(int n, double dx, pd_vec3 *v, int v0, int (*tri)[3], int t0)
{
    pd_vec3 ax = v3_unit(v3(1, 2, 3));
    double th = 0.7, co = cos(th), si = sin(th);
    for (int e = 0; e < 2; e++)
        for (int i = 0; i < n; i++) {
            double a = 2.0 * M_PI * i / n;
            pd_vec3 p = v3(e, 0.05 * cos(a) + dx, 0.05 * sin(a));
            p = v3_add(v3_add(v3_scale(p, co), v3_scale(v3_cross(ax, p), si)),
                       v3_scale(ax, v3_dot(ax, p) * (1.0 - co)));
            v[v0 + e * n + i] = p;
        }
    int t = t0;
    for (int i = 0; i < n; i++) {
        int j = (i + 1) % n;
        int q[2][3] = {{i, j, n + j}, {i, n + j, n + i}};
        for (int h = 0; h < 2; h++, t++)
            for (int k = 0; k < 3; k++)
                tri[t][k] = v0 + q[h][k];
    }
    for (int i = 1; i < n - 1; i++, t += 2)
        for (int k = 0; k < 3; k++) {
            int f0[3] = {0, i + 1, i}, f1[3] = {n, n + i, n + i + 1};
            tri[t][k] = v0 + f0[k];
            tri[t + 1][k] = v0 + f1[k];
        }
}

/* The rod of docs/limits.md: long slivers across every axis, and caps fanned
 * about one corner, flat only to round-off. The pairs that reach the exact
 * test grow in proportion to the triangles (a search whose pairs grow as
 * their square, as a sort and sweep of axis-aligned boxes did, tests 16
 * times more per triangle at 16 times the sides); two such rods, one moved
 * across the other by half its radius, cross, and the pair named does.
 * Two rods four radii apart, not one: a single rod is star-shaped and
 * settled before the search (test_self_crossing_star). */
static void test_self_crossing_rod(void)
{
    double per[2];
    int sides[2] = {250, 4000};
    for (int r = 0; r < 2; r++) {
        int n = sides[r], nt = 2 * (2 * n - 2);
        pd_vec3 *v = malloc(sizeof *v * 4 * (size_t)n);
        int(*tri)[3] = malloc(sizeof *tri * 2 * (size_t)nt);
        turned_rod(n, 0.0, v, 0, tri, 0);
        turned_rod(n, 0.2, v, 2 * n, tri, nt);
        pd_mesh m = {4 * n, v, 2 * nt, tri};
        int ta, tb;
        pd_vec3 at;
        size_t tested;
        CHECK_STATUS(pd_mesh_self_crossing(&m, NULL, &ta, &tb, &at, &tested), PD_OK);
        CHECK_INT(ta, -1);
        CHECK(tested > 0);
        per[r] = (double)tested / (2 * nt);
        pd_note("self-crossing, turned rod of %d sides (%d triangles): %zu pairs tested, %.2f "
                "per triangle\n", n, nt, tested, per[r]);
        if (r == 0) {
            turned_rod(n, 0.025, v, 2 * n, tri, nt);
            pd_mesh two = {4 * n, v, 2 * nt, tri};
            CHECK_STATUS(pd_mesh_self_crossing(&two, NULL, &ta, &tb, &at, NULL), PD_OK);
            CHECK(ta >= 0 && ta < nt && tb >= nt);
        }
        free(v);
        free(tri);
    }
    /* Near-linear: a factor 2 allows for the log of the tree's depth and
     * the corner fans' overlaps; quadratic growth gives 16. */
    CHECK(per[1] < 2.0 * per[0]);
}

/* A latitude-longitude sphere of m x m vertices and two poles about c,
 * outward (counter-clockwise seen from outside), the radius of each vertex
 * r (1 + noise u), u uniform in [-1, 1]: 2 m^2 triangles from t0 on, m^2 + 2
 * vertices from v0 on. */
static void uv_sphere(int m, pd_vec3 c, double r, double noise, test_rng *g, pd_vec3 *v, int v0,
                      int (*tri)[3], int t0)
{
    int np = m * m, t = t0;
    v[v0 + np] = v3_add(c, v3(0, 0, r * (1.0 + noise * rng_range(g, -1, 1))));
    v[v0 + np + 1] = v3_add(c, v3(0, 0, -r * (1.0 + noise * rng_range(g, -1, 1))));
    for (int i = 0; i < m; i++)
        for (int j = 0; j < m; j++) {
            double th = M_PI * (i + 1) / (m + 1), ph = 2.0 * M_PI * j / m;
            double rr = r * (1.0 + noise * rng_range(g, -1, 1));
            v[v0 + i * m + j] = v3_add(c, v3(rr * sin(th) * cos(ph), rr * sin(th) * sin(ph),
                                             rr * cos(th)));
        }
    for (int j = 0; j < m; j++) {
        int k = (j + 1) % m;
        int a[3] = {np, j, k}, b[3] = {np + 1, (m - 1) * m + k, (m - 1) * m + j};
        for (int q = 0; q < 3; q++) {
            tri[t][q] = v0 + a[q];
            tri[t + 1][q] = v0 + b[q];
        }
        t += 2;
        for (int i = 0; i + 1 < m; i++) {
            int p00 = i * m + j, p01 = i * m + k, p10 = (i + 1) * m + j, p11 = (i + 1) * m + k;
            int x[3] = {p00, p10, p11}, y[3] = {p00, p11, p01};
            for (int q = 0; q < 3; q++) {
                tri[t][q] = v0 + x[q];
                tri[t + 1][q] = v0 + y[q];
            }
            t += 2;
        }
    }
}

/* The shortcut before the search: a closed surface whose triangles all face
 * one point and which a line through that point pierces twice cannot cross
 * itself. Settled without a pair tested: the turned rod, a sphere whose
 * corners have radii drawn in [0.5, 1] (the noisy scan of docs/performance.md,
 * its kernel a small region about the centre), the same sphere at the side
 * of the origin. Left to the search (pairs tested), with the answer of the
 * search: two nested spheres (every triangle faces the centre, but lines
 * through it pierce four: no crossing), two overlapping spheres (the same,
 * and they cross), a sphere with one triangle turned over (closed, not
 * consistently oriented), a sphere with one vertex pushed through the far
 * side (it crosses), two spheres apart (no point faces all: the search
 * then takes only the second sphere and the triangles of the first that
 * it hides from the first's centre), the same with a vertex of the first
 * pushed through its far side (found). */
static void test_self_crossing_star(void)
{
    enum { M = 24, NT = 2 * M * M, NV = M * M + 2 };
    pd_vec3 *v = malloc(sizeof *v * 2 * NV);
    int(*tri)[3] = malloc(sizeof *tri * 2 * NT);
    test_rng g = {7};
    int ta, tb;
    pd_vec3 at;
    size_t tested;
    struct {
        const char *what;
        pd_vec3 c2;     /* the second sphere's centre; none when r2 == 0 */
        double r2, noise, off;
        int flip, push, crosses, shortcut;
    } cases[] = {
        {"noisy sphere", {0, 0, 0}, 0, 0.333, 0, 0, 0, 0, 1},
        {"noisy sphere off the origin", {0, 0, 0}, 0, 0.333, 5.0, 0, 0, 0, 1},
        {"nested spheres", {0, 0, 0}, 0.5, 0.01, 0, 0, 0, 0, 0},
        {"overlapping spheres", {0.3, 0.1, 0}, 1.0, 0.01, 0, 0, 0, 1, 0},
        {"one triangle turned over", {0, 0, 0}, 0, 0.01, 0, 1, 0, 0, 0},
        {"a vertex pushed through", {0, 0, 0}, 0, 0.01, 0, 0, 1, 1, 0},
        {"spheres apart", {3, 0, 0}, 1.0, 0.01, 0, 0, 0, 0, 0},
        {"spheres apart, a vertex pushed through", {3, 0, 0}, 1.0, 0.01, 0, 0, 1, 1, 0},
        {"noisy spheres apart, a vertex pushed through", {3, 0, 0}, 1.0, 0.333, 0, 0, 1, 1, 0},
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        /* noise 0.333: radii in [0.667, 1.333], twice the smallest. */
        pd_vec3 c1 = v3(cases[c].off, 0, 0);
        uv_sphere(M, c1, 1.0, cases[c].noise, &g, v, 0, tri, 0);
        int nv = NV, nt = NT;
        if (cases[c].r2 > 0) {
            uv_sphere(M, v3_add(c1, cases[c].c2), cases[c].r2, cases[c].noise, &g, v, NV, tri, NT);
            nv += NV;
            nt += NT;
        }
        if (cases[c].flip) {
            int x = tri[100][1];
            tri[100][1] = tri[100][2];
            tri[100][2] = x;
        }
        if (cases[c].push)
            v[5 * M + 3] = v3_add(c1, v3_scale(v3_sub(v[5 * M + 3], c1), -1.5));
        pd_mesh m = {nv, v, nt, tri};
        CHECK_STATUS(pd_mesh_self_crossing(&m, NULL, &ta, &tb, &at, &tested), PD_OK);
        if ((ta >= 0) != cases[c].crosses || (tested == 0) != cases[c].shortcut)
            pd_note("self-crossing, %s: crossing %d, %zu pairs tested\n", cases[c].what, ta >= 0,
                    tested);
        CHECK_INT(ta >= 0, cases[c].crosses);
        CHECK_INT(tested == 0, cases[c].shortcut);
    }
    int n = 400, rnt = 2 * (2 * n - 2);
    pd_vec3 *rv = malloc(sizeof *rv * 2 * (size_t)n);
    int(*rt)[3] = malloc(sizeof *rt * (size_t)rnt);
    turned_rod(n, 0.0, rv, 0, rt, 0);
    pd_mesh rod = {2 * n, rv, rnt, rt};
    CHECK_STATUS(pd_mesh_self_crossing(&rod, NULL, &ta, &tb, &at, &tested), PD_OK);
    CHECK_INT(ta, -1);
    CHECK_INT((int)tested, 0);
    free(rv);
    free(rt);
    free(v);
    free(tri);
}

/* A cancel set by another thread after a given delay. */
typedef struct {
    pd_cancel_flag *flag;
    long delay_ns;
} late_cancel;

static void *cancel_later(void *arg)
{
    const late_cancel *c = arg;
    struct timespec ts = {c->delay_ns / 1000000000L, c->delay_ns % 1000000000L};
    nanosleep(&ts, NULL);
    atomic_store(c->flag, 1);
    return NULL;
}

/* A cancel that lands anywhere in the check of a part that is not
 * star-shaped (two spheres apart: the narrowing, the part's search, its
 * flat patches and tree) ends it cleanly: PD_OK with the uncancelled
 * answer (no crossing) when the check finished first, else
 * PD_ERR_CANCELLED with no pair named; never a crash or a sanitizer report
 * (a cancelled union-find was once read uninitialised). The moments are
 * spread over the check's own duration, measured first; which stages they
 * hit varies from run to run, what each must answer does not. */
static void test_self_crossing_cancelled(void)
{
    enum { M = 90, NT = 2 * M * M, NV = M * M + 2, MOMENTS = 64 };
    pd_vec3 *v = malloc(sizeof *v * 2 * NV);
    int(*tri)[3] = malloc(sizeof *tri * 2 * NT);
    test_rng g = {11};
    uv_sphere(M, v3(0, 0, 0), 1.0, 0.01, &g, v, 0, tri, 0);
    uv_sphere(M, v3(3, 0, 0), 1.0, 0.01, &g, v, NV, tri, NT);
    pd_mesh m = {2 * NV, v, 2 * NT, tri};
    int ta, tb;
    pd_vec3 at;
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    CHECK_STATUS(pd_mesh_self_crossing(&m, NULL, &ta, &tb, &at, NULL), PD_OK);
    clock_gettime(CLOCK_MONOTONIC, &t1);
    CHECK_INT(ta, -1);
    long span = (t1.tv_sec - t0.tv_sec) * 1000000000L + (t1.tv_nsec - t0.tv_nsec);
    int bad = 0, cancelled = 0;
    for (int k = 0; k < MOMENTS; k++) {
        pd_cancel_flag flag = 0;
        late_cancel c = {&flag, span * k / MOMENTS};
        pthread_t th;
        if (pthread_create(&th, NULL, cancel_later, &c) != 0)
            continue;
        pd_status st = pd_mesh_self_crossing(&m, &flag, &ta, &tb, &at, NULL);
        pthread_join(th, NULL);
        cancelled += st == PD_ERR_CANCELLED;
        bad += !((st == PD_OK || st == PD_ERR_CANCELLED) && ta == -1 && tb == -1);
    }
    pd_note("self-crossing cancelled at %d moments over %.3f s: %d cancelled\n", MOMENTS,
            1e-9 * (double)span, cancelled);
    CHECK_INT(bad, 0);
    free(v);
    free(tri);
}

/* Exact signs of triangle p's corners against the plane of q: 1 when one is
 * strictly positive and one strictly negative (a shared corner counts 0). */
static int exact_straddle(const pd_vec3 *v, const int p[3], const int q[3])
{
    int pos = 0, neg = 0;
    for (int i = 0; i < 3; i++) {
        if (p[i] == q[0] || p[i] == q[1] || p[i] == q[2])
            continue;
        int s = pd_orient3d_exact(&v[q[0]], &v[q[1]], &v[q[2]], &v[p[i]]);
        pos += s > 0;
        neg += s < 0;
    }
    return pos && neg;
}

/* The plane filter in front of the exact test never sets aside a pair in
 * which each triangle straddles the other's plane (exact signs), on random
 * pairs whose second triangle's corners lie on the first's plane to
 * rounding, then moved off it by 0 to 1e-1 of the triangle's size, with
 * corners shared, at offsets from the origin up to 1e4 times the size and
 * sizes from 1e-6 to 1e6. It does set aside every pair moved clearly to one
 * side (by 1e-2 of the size, near the origin), or it would save nothing. */
static void test_self_crossing_filter(void)
{
    test_rng rng = {20261207};
    int wrong = 0, straddling = 0, clear = 0, clear_kept = 0, trials = 200000;
    for (int it = 0; it < trials; it++) {
        double L = pow(10.0, -6.0 + 12.0 * rng_uniform(&rng));
        double off = rng_uniform(&rng) < 0.5 ? 0.0 : L * pow(10.0, 4.0 * rng_uniform(&rng));
        pd_vec3 v[6];
        for (int i = 0; i < 3; i++)
            v[i] = v3(off + L * (rng_uniform(&rng) - 0.5), off * 0.3 + L * (rng_uniform(&rng) - 0.5),
                      -off + L * (rng_uniform(&rng) - 0.5));
        pd_vec3 n = v3_unit(v3_cross(v3_sub(v[1], v[0]), v3_sub(v[2], v[0])));
        int one_way = rng_uniform(&rng) < 0.5;
        double h = rng_uniform(&rng) < 0.3 ? 0.0 : L * pow(10.0, -16.0 + 15.0 * rng_uniform(&rng));
        for (int i = 3; i < 6; i++) {
            double a = 2.0 * rng_uniform(&rng) - 0.5, b = 2.0 * rng_uniform(&rng) - 0.5;
            pd_vec3 on = v3_add(v[0], v3_add(v3_scale(v3_sub(v[1], v[0]), a),
                                            v3_scale(v3_sub(v[2], v[0]), b)));
            double side = one_way ? 1.0 : (rng_uniform(&rng) < 0.5 ? -1.0 : 1.0);
            v[i] = v3_add(on, v3_scale(n, side * h * (0.5 + rng_uniform(&rng))));
        }
        int p[3] = {0, 1, 2}, q[3] = {3, 4, 5};
        double u = rng_uniform(&rng);
        if (u < 0.2)
            q[0] = 0;
        if (u < 0.05)
            q[1] = 1;
        double R = 0.0;
        for (int i = 0; i < 6; i++)
            R = fmax(R, fmax(fabs(v[i].x), fmax(fabs(v[i].y), fabs(v[i].z))));
        int set_aside = pd_selfx_plane_filter(v, p, q, R);
        int both = exact_straddle(v, p, q) && exact_straddle(v, q, p);
        straddling += both;
        wrong += set_aside && both;
        if (one_way && off == 0.0 && h >= 1e-2 * L && q[0] != 0) {
            clear++;
            clear_kept += !set_aside;
        }
    }
    pd_note("self-crossing filter, %d pairs: %d straddle each other exactly, %d clearly apart\n",
            trials, straddling, clear);
    CHECK_INT(wrong, 0);
    /* The near-degenerate cases the filter must not decide occur. */
    CHECK(straddling > trials / 100);
    CHECK(clear > 100);
    CHECK_INT(clear_kept, 0);
}

void suite_mesh(void)
{
    test_off();
    test_off_bad();
    test_stl_ascii();
    test_stl_binary();
    test_obj();
    test_vertex_rest();
    test_format();
    test_units();
    test_files();
    test_prefixes();
    test_weld();
    test_clone_size();
    test_self_crossing();
    test_self_crossing_many();
    test_self_crossing_rod();
    test_self_crossing_star();
    test_self_crossing_cancelled();
    test_self_crossing_filter();
}
