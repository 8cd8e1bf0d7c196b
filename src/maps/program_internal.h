/* program_internal.h: the parsed form of a DOOM 3 image program, shared by
 * program_parse.c (text -> tree) and program.c (tree -> image). */
#ifndef BB_PROGRAM_INTERNAL_H
#define BB_PROGRAM_INTERNAL_H

#include "bumpbake.h"

/* A parsed DOOM 3 image program, such as "addnormals(a_local.tga,
 * heightmap(a_h.tga, 4))": opaque, made by bb__program_parse (once public: a
 * client runs a program through its command, bb_command_program). */
typedef struct bb__program bb__program;

/* Parses text in DOOM 3's image-program syntax: heightmap(img, scale),
 * addnormals(a, b), smoothnormals(a), add(a, b), scale(a, r, g, b, a),
 * invertAlpha(a), invertColor(a), makeIntensity(a), makeAlpha(a), _flat, and
 * image names (file paths; "double quotes" allow spaces and commas). Function
 * names are case-insensitive, as in id Tech 4. A syntax error is
 * BB_ERR_ARGUMENT with a message giving the 1-based column; an unknown
 * function's message lists the known ones. Free *out with bb__program_free. */
bb_status bb__program_parse(const char *text, bb__program **out, bb_error *err);

void bb__program_free(bb__program *program);

/* Reads the image a program names: fills img (any channel count) and info
 * (may be NULL) as bb_image_read does. */
typedef bb_status (*bb__image_loader)(void *user, const char *path, bb_image *img,
                                     bb_image_info *info, bb_error *err);

typedef struct bb__program_options {
  const char *base_dir;   /* image names are relative to it; NULL or "" = the
                             current directory */
  int allow_outside_base; /* 0 (default): an image name must stay inside the
                             base directory, resolved (no absolute path, no
                             "..", no symbolic link out: BB_ERR_ARGUMENT);
                             1: any file may be read */
  bb__image_loader loader; /* NULL = bb_image_read */
  void *loader_user;
} bb__program_options;

void bb__program_options_init(bb__program_options *o);

/* Evaluates a program as id Tech 4 does (docs/commands/program.md gives each
 * formula), in float rather than bytes. Inside, every image is RGBA in
 * [0, 1] standing for id's bytes / 255 (files are read as value / max code,
 * clamped; grey gives R = G = B, no alpha gives A = 1), and normal-map
 * operations decode N = (255 v - 128) / 127 and encode v = (127 N + 128) /
 * 255, id's own mapping (byte 128 is 0). When the program makes a normal map
 * (heightmap, addnormals, smoothnormals or _flat anywhere in it, as id marks
 * TD_BUMP), out holds its decoded N (3 channels, +Y down) and *is_normal_map
 * is 1; otherwise out holds RGBA colour (4 channels) and *is_normal_map is 0.
 * Errors name the file or the function and its column. */
bb_status bb__program_run(const bb__program *program, const bb__program_options *o,
                         bb_image *out, int *is_normal_map, bb_error *err);


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

struct bb__program {
  prog_node *root;
};

/* The name of an operation as DOOM 3 spells it ("heightmap", "invertAlpha"). */
const char *bb__program_op_name(prog_op op);

/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* The image names a program reads, in the order it reads them (as written,
 * unquoted; _flat is not a file and is left out): up to cap of them into
 * names (pointers into the program, valid until bb__program_free). Returns
 * how many there are, which may exceed cap. For dependency tracking, as
 * id's timestamps, and to keep an output from replacing an input. */
size_t bb__program_images(const bb__program *program, const char **names, size_t cap);

/* The file a program's image name is read from: name as written when it is
 * absolute or base_dir is NULL or empty, else base_dir/name (base_dir as in
 * bb__program_options). Writes it into out (cap bytes, terminated) and
 * returns its length, as snprintf does: a length >= cap means it did not
 * fit, and bb__program_run refuses such a name rather than read a cut path. */
int bb__program_image_path(const char *base_dir, const char *name, char *out, size_t cap);

#endif /* BB_PROGRAM_INTERNAL_H */
