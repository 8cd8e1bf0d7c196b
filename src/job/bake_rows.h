/* bake_rows.h: the bake's options described once, below the commands (not
 * public): each row is an option's name, where its value is in
 * bb_job_options and how the value is written as the command line takes
 * it. The commands family's rows of these options (cmd/options_bake.c)
 * point at them for their name, field, words and printing, and add what
 * only a command needs (help, ranges, parsers, rules); a command is
 * spelled back through them by bb_command_text, the library's one
 * speller of command lines. Also the kinds of field a value is and the
 * library's enums as words (enums.c), which both families use. */
#ifndef BB_JOB_BAKE_ROWS_H
#define BB_JOB_BAKE_ROWS_H

#include "bumpbake.h"
#include "core/internal.h"
#include "job/job_options.h"

#include <stddef.h>

/* Where an option's value goes: the kind of its field. */
typedef enum bb__field {
  BB__FIELD_NONE = 0, /* the option's set function writes it */
  BB__FIELD_INT,      /* int (flags set 1) */
  BB__FIELD_FLOAT,
  BB__FIELD_DOUBLE,
  BB__FIELD_STRING, /* const char *, owned by the command */
  BB__FIELD_ENUM,   /* an enum, stored as int (enums of the API are int-sized) */
  BB__FIELD_ANGLES, /* AZ,EL: double azimuth, then double elevation (the range's);
                       sets (bb__flag_sets) turns the light or camera on */
  BB__FIELD_KEPT    /* in no field: the text given is its value, read with
                       bb_command_value (a client's own option: serve's
                       --port and --address); not given, its default_text */
} bb__field;

/* An enum's name for value i ("unknown" or NULL past the last), and its
 * parser (with the enum's aliases and case rules): BB_OK and *value, or
 * BB_ERR_ARGUMENT with the value's own words in err (may be NULL: "channel
 * must be one of auto, r, ... (got 'z')"), which bb_option_parse gives a
 * client; the command line's parser words it by the option instead. */
typedef const char *(*bb__name_fn)(int i);
typedef bb_status (*bb__parse_fn)(const char *text, long long *value, bb_error *err);

/* What a FLAG sets when given besides its own field (if any): the field at
 * offset to value (INT, ENUM) or to text (STRING, a constant). field NONE:
 * nothing. A flag that sets one cannot be unset ("0"). offset is in the
 * struct the row describes: bb_job_options for a bake row, and
 * bb_command_options for a row of the commands' own. */
typedef struct bb__flag_sets {
  bb__field field;
  size_t offset;
  int value;
  const char *text;
} bb__flag_sets;

typedef struct bb__bake_row {
  char name[24];   /* the option without "--": its one spelling (an array,
                      so a command's row can name it in a constant) */
  int flag;        /* takes no value */
  bb__field field; /* the value, at offset in bb_job_options */
  size_t offset;
  bb__name_fn names;  /* an enum's words (ENUM, and INT read as a word) */
  bb__flag_sets sets; /* a flag's other field, in bb_job_options */
  /* the value as the option takes it; NULL: by field */
  void (*print)(const bb_job_options *o, bb__text *t);
} bb__bake_row;

/* The rows, one per option of `bumpbake bake` that determines the output,
 * each named by its option (-- and '-' as '_'). */
extern const bb__bake_row bb__row_scale, bb__row_rays, bb__row_slices,
    bb__row_filter_radius, bb__row_filter_threshold, bb__row_bias, bb__row_power,
    bb__row_basis, bb__row_normal_filter, bb__row_normal_y, bb__row_clamp,
    bb__row_channel, bb__row_depth, bb__row_mips, bb__row_bounce, bb__row_bounces,
    bb__row_bounce_albedo, bb__row_brightness, bb__row_normal, bb__row_weights,
    bb__row_ssbump, bb__row_ao, bb__row_bent, bb__row_filtered, bb__row_slope,
    bb__row_lit, bb__row_out_dir, bb__row_maps, bb__row_name, bb__row_texture_format,
    bb__row_vtf_version, bb__row_vtf_flags, bb__row_nomip, bb__row_fast_compression,
    bb__row_vmt, bb__row_materials, bb__row_basetexture;

/* Row r's value in o as the option takes it (nothing for a flag), a
 * number as a user types it (bb__float_text: "30", "36.8083"). */
void bb__bake_row_value(const bb__bake_row *r, const bb_job_options *o, bb__text *t);

/* A value of kind field at `at` as an option takes it: an enum's word (by
 * names), a number, a string, "AZ,EL"; nothing for a flag (flag) or NONE. */
void bb__field_text(bb__field field, int flag, bb__name_fn names, const void *at,
                    bb__text *t);

/* Enums as words (enums.c): bb__name_X and bb__parse_X of each. */
#define BB__ENUM_WORDS(stem)                                                             \
  const char *bb__name_##stem(int i);                                                    \
  bb_status bb__parse_##stem(const char *text, long long *value, bb_error *err);
BB__ENUM_WORDS(normal_filter)
BB__ENUM_WORDS(channel)
BB__ENUM_WORDS(texture_format)
BB__ENUM_WORDS(render_mode)
BB__ENUM_WORDS(albedo_mode)
BB__ENUM_WORDS(axis)
BB__ENUM_WORDS(map_kind)
BB__ENUM_WORDS(depth)
BB__ENUM_WORDS(normal_y)
BB__ENUM_WORDS(ssbump_kind)
BB__ENUM_WORDS(output_kind)

/* The defaults of bake (bb__bake_options_init), channel AUTO, BB_DEPTH_DEFAULT,
 * the texture defaults (bb_texture_options_init), no outputs. */
void bb__job_options_init(bb_job_options *o);

#endif /* BB_JOB_BAKE_ROWS_H */
