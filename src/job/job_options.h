/* job_options.h: how an output was made (bb_provenance) and a job's
 * options (bb_job_options), the structs a command fills for the job it
 * plans. Once in bumpbake.h; internal since issue 41, as they change with
 * every feature: clients plan through a command (bb_command_plan) and read
 * a bake's settings by name (bb_command_value) or through calls on the
 * command and its job. */
#ifndef BB_JOB_JOB_OPTIONS_H
#define BB_JOB_JOB_OPTIONS_H

#include "bake/bake_internal.h"
#include "bumpbake.h"

/* How an output was made. Every field that affects pixels is here. */
typedef struct bb_provenance {
  const char *command;        /* the command line, or NULL */
  const char *input_name;     /* input file name (no directory), or NULL */
  uint64_t input_hash;        /* the hash of the decoded input pixels */
  const char *output_kind;    /* "normal", "ssbump", "ao", ... */
  const bb_bake_options *options;
  bb_channel channel;         /* height channel rule used */
  const char *rayset_id;      /* bb_rayset_id, or NULL when nothing was traced */
  uint64_t input_file_hash;   /* bb_file_hash of the input file's bytes, or 0:
                                 unknown (the key is then left out) */
  const char *extra;          /* "key=value" lines appended as they are (a
                                 render's or a render bump's own keys), or NULL */
} bb_provenance;

typedef struct bb_job_options {
  bb_bake_options bake;      /* every bake parameter; .outputs is set from
                                the maps asked */
  bb_channel channel;        /* the height channel rule (default AUTO) */
  bb_depth depth;            /* every map's depth; BB_DEPTH_DEFAULT: the
                                format's, and the filtered height keeps the
                                input's */
  int mips;                  /* 1: mip-mapped files (.tif, .tiff, .exr) */
  const char *basis_file;    /* the file bake.basis came from, or NULL: a
                                prerequisite in the depfile */
  const char *bounce_albedo_file; /* an albedo map for inter-reflection
                                (bake.bounce_albedo_map), read once by the plan.
                                NULL: none */
  const char *brightness_file; /* a brightness map (bake.brightness), read once
                                by the plan, or NULL */
  /* One input, outputs named one by one (out_dir NULL): */
  const char *paths[BB_MAP_BAKED_COUNT]; /* by bb_map_kind; NULL = not written */
  const char *prefix;        /* also PREFIX_KIND.png for each of
                                BB_JOB_DEFAULT_MAPS not named in paths, or NULL */
  const char *slope_path;    /* flipcode's slope map (8-bit .png .tga .tif), or NULL */
  int slope_lit;             /* 1: also slope_path with "_lit" before its
                                extension, the map lit through its table */
  double slope_lit_azimuth, slope_lit_elevation; /* degrees, as render's --light;
                                azimuth finite, elevation 0..90 */
  /* A batch (out_dir set): */
  const char *out_dir;       /* outputs go to out_dir/name; created when missing */
  const char *name_template; /* NULL: BB_JOB_DEFAULT_NAME; "{kind}/{stem}.png"
                                makes subfolders, created as needed; a name
                                must stay inside out_dir */
  unsigned maps;             /* BB_MAP_BIT(kind)s; 0: BB_JOB_DEFAULT_MAPS */
  int force;                 /* 1: bake inputs whose outputs are up to date too */
  int keep_going;            /* 1: go on after an input fails (bb_job_run) */
  const char *depfile;       /* a Make/Ninja depfile to write, or NULL */
  /* Provenance: the "command" key. */
  const char *command;       /* one input: the whole command line as typed */
  const char *command_options; /* what follows "bumpbake bake INPUT" in each
                                output's command (a batch's, or a single input's
                                when command is NULL); bb_command_plan sets
                                them (a plan without either is refused) */
  bb_note_fn note;           /* notes about inputs (may be NULL) */
  void *note_user;
  /* Engine textures and a Source material: */
  bb_texture_options texture; /* the settings of every .vtf and .dds output
                                (format, mips, VTF version and flags); each
                                one's map follows its kind
                                and range; threads 0: the bake's. Sizes and channels are
                                checked against the input's header when planned */
  const char *vmt;           /* one input: a Source material (.vmt) written with
                                the maps, its $bumpmap the ssbump .vtf (with
                                $ssbump 1), else the normal map's .vtf; NULL: none */
  const char *vmt_materials; /* the game's materials folder the material's paths
                                are relative to; NULL: the nearest folder named
                                "materials" above the bump map (bb_vmt_options) */
  const char *vmt_basetexture; /* the colour .vtf the material names, or NULL */
  /* Valve's height2ssbump file (one input, no out_dir): */
  const char *valve_path;    /* the RGBA file Valve's tool makes of the bake (RGB
                                ssbump or normal map, A filtered height or ao), written
                                before the maps; NULL: none. Its provenance names the
                                channel the height came from, as Valve's rule picks it */
  bb_valve_options valve;    /* what goes into it */
  int valve_detail;          /* 1: Valve's detail variant (RGB times the
                                input's smoothed colour); not with valve.normal_map */
} bb_job_options;

#endif /* BB_JOB_JOB_OPTIONS_H */
