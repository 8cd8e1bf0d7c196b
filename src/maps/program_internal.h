/* program_internal.h: the parsed form of a DOOM 3 image program, shared by
 * program_parse.c (text -> tree) and program.c (tree -> image). */
#ifndef BB_PROGRAM_INTERNAL_H
#define BB_PROGRAM_INTERNAL_H

#include "bumpbake.h"


/* Deepest nesting the parser accepts, so a hostile program cannot exhaust
 * the stack of either the parser or the evaluator. */
#define BB__PROGRAM_MAX_DEPTH 64

typedef enum prog_op {
  PROG_IMAGE = 0,  /* a file; name holds its path */
  PROG_FLAT,       /* _flat: the flat normal map */
  PROG_HEIGHTMAP,  /* heightmap(a, scale) */
  PROG_ADDNORMALS, /* addnormals(a, b) */
  PROG_SMOOTHNORMALS,
  PROG_ADD,   /* add(a, b) */
  PROG_SCALE, /* scale(a, r, g, b, a) */
  PROG_INVERT_ALPHA,
  PROG_INVERT_COLOR,
  PROG_MAKE_INTENSITY,
  PROG_MAKE_ALPHA
} prog_op;

typedef struct prog_node {
  prog_op op;
  int column;                /* 1-based column of the function name or image name */
  char *name;                /* PROG_IMAGE: the path as written (unquoted) */
  double numbers[4];         /* heightmap: [0] = scale; scale: the four factors */
  struct prog_node *args[2]; /* image operands, in order */
} prog_node;

struct bb_program {
  prog_node *root;
};

/* The name of an operation as DOOM 3 spells it ("heightmap", "invertAlpha"). */
const char *bb__program_op_name(prog_op op);

/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* The image names a program reads, in the order it reads them (as written,
 * unquoted; _flat is not a file and is left out): up to cap of them into
 * names (pointers into the program, valid until bb_program_free). Returns
 * how many there are, which may exceed cap. For dependency tracking, as
 * id's timestamps, and to keep an output from replacing an input. */
size_t bb__program_images(const bb_program *program, const char **names, size_t cap);

/* The file a program's image name is read from: name as written when it is
 * absolute or base_dir is NULL or empty, else base_dir/name (base_dir as in
 * bb_program_options). Writes it into out (cap bytes, terminated) and
 * returns its length, as snprintf does: a length >= cap means it did not
 * fit, and bb_program_run refuses such a name rather than read a cut path. */
int bb__program_image_path(const char *base_dir, const char *name, char *out, size_t cap);

#endif /* BB_PROGRAM_INTERNAL_H */
