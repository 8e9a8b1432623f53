/* xmlcheck.h: a small XML well-formedness checker for the tests of the SVG
 * and HTML writers (no XML library is a dependency). */
#ifndef PD_TEST_XMLCHECK_H
#define PD_TEST_XMLCHECK_H

#include <stddef.h>

/* Checks that text is one well-formed XML document (an optional XML
 * declaration and <!DOCTYPE ...>, comments, one root element): names,
 * quoted attributes without '<' and without repeats, balanced tags, and
 * only the five predefined entities or numeric character references. When
 * allowed is not NULL (a NULL-terminated list), every element name must be
 * in it. Returns 1 when well-formed; else 0 with a message in err. */
int xml_check(const char *text, const char *const *allowed, char *err, size_t errsize);

/* The SVG 1.1 elements posedrop writes. */
extern const char *const xml_svg11_elements[];

#endif
