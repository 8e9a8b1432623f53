/* text_width.c: how wide a line of the pictures' text is, for their layout
 * and its test. */
#include "viz/viz_internal.h"

/* Advance widths of the printable ASCII characters (' ' to '~') in DejaVu
 * Sans and DejaVu Sans Bold, in 1/2048 em: the hmtx table of the fonts of
 * Debian's fonts-dejavu-core 2.37, the first family the pictures name
 * (draw.c's font-family; make check-browser installs and renders with it).
 * Kerning is left out, as it narrows a line more often than it widens it by
 * a fraction of a pixel. The fall-backs named after it, Helvetica and Arial,
 * set a line of lower-case text and digits 10-15% narrower, though a few
 * capitals and '_' are wider; the layout's gaps take those. */
static const unsigned short advance[2][95] = {
    {
        651, 821, 942, 1716, 1303, 1946, 1597, 563, 799, 799, 1024, 1716,
        651, 739, 651, 690, 1303, 1303, 1303, 1303, 1303, 1303, 1303, 1303,
        1303, 1303, 690, 690, 1716, 1716, 1716, 1087, 2048, 1401, 1405, 1430,
        1577, 1294, 1178, 1587, 1540, 604, 604, 1343, 1141, 1767, 1532, 1612,
        1235, 1612, 1423, 1300, 1251, 1499, 1401, 2025, 1403, 1251, 1403, 799,
        690, 799, 1716, 1024, 1024, 1255, 1300, 1126, 1300, 1260, 721, 1300,
        1298, 569, 569, 1186, 569, 1995, 1298, 1253, 1300, 1300, 842, 1067,
        803, 1298, 1212, 1675, 1212, 1212, 1075, 1303, 690, 1303, 1716,
    },
    {
        713, 934, 1067, 1716, 1425, 2052, 1786, 627, 936, 936, 1071, 1716,
        778, 850, 778, 748, 1425, 1425, 1425, 1425, 1425, 1425, 1425, 1425,
        1425, 1425, 819, 819, 1716, 1716, 1716, 1188, 2048, 1585, 1561, 1503,
        1700, 1399, 1399, 1681, 1714, 762, 762, 1587, 1305, 2038, 1714, 1741,
        1501, 1741, 1577, 1475, 1397, 1663, 1585, 2259, 1579, 1483, 1485, 936,
        748, 936, 1716, 1024, 1024, 1382, 1466, 1214, 1466, 1389, 891, 1466,
        1458, 702, 702, 1362, 702, 2134, 1458, 1407, 1466, 1466, 1010, 1219,
        979, 1458, 1335, 1892, 1321, 1335, 1192, 1458, 748, 1458, 1716,
    },
};

/* A character beyond ASCII (a degree sign, a multiplication sign, a letter
 * of a file name): wider than any of the fonts' Latin-1 and Latin
 * Extended-A glyphs (at most 2191 and 2390). */
#define WIDE_GLYPH 2400

double viz_text_width(const char *text, double size, int bold)
{
    long units = 0;
    for (const unsigned char *p = (const unsigned char *)text; *p; p++) {
        if (*p >= 32 && *p < 127)
            units += advance[bold != 0][*p - 32];
        else if (*p >= 0xc0 || *p < 0x80) /* a UTF-8 lead byte (or a control) */
            units += WIDE_GLYPH;
    }
    return size * (double)units / 2048.0;
}
