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

#endif /* BB_PROGRAM_INTERNAL_H */
