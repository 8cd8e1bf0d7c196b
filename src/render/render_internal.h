/* render_internal.h: what the render family shares with the families above
 * it (not public): the ranges of bb_render_options' fields, each written
 * once in render.c and referred to by the options that set them (cmd/) and
 * by the job's lit slope preview. */
#ifndef BB_RENDER_INTERNAL_H
#define BB_RENDER_INTERNAL_H

#include "bake/bake_internal.h"
#include "core/internal.h"

/* Once in bumpbake.h (issue 41): no public function takes them; the
 * render, sheet and job families do. */

/* What one render shows and how it is lit (the command's options: render's
 * and sheet's picture; bb_command_set_picture for what no option spells). */
typedef struct bb_render_options {
  bb_render_mode mode;          /* default BB_RENDER_SSBUMP */
  int dynamic_light;            /* 1: the dynamic light is on (default 1) */
  double light_azimuth;         /* degrees, any finite value (default 135) */
  double light_elevation;       /* degrees, 0..90 (default 45) */
  float light_color[3];         /* C, >= 0 (default 1, 1, 1) */
  int static_light;             /* 1: the lightmaps are on (default 0) */
  float lightmap[3][3];         /* L_c, >= 0; default red, green, blue: the
                                   three basis directions in three colours */
  double specular_exponent;     /* k in 0..BB_MAX_SPECULAR_EXPONENT, 0 = no specular
                                   (default 0) */
  double specular_strength;     /* ks, 0..1000: the highlight's scale, a
                                   material's specular intensity (default 1) */
  bb_albedo_mode albedo_mode;   /* how maps->albedo multiplies the diffuse light;
                                   default BB_ALBEDO_MULTIPLY */
  int tile_x, tile_y;           /* repeat the render nx x ny, 1..64 (default 1, 1) */
  int crop_x, crop_y, crop_width, crop_height; /* window of the tiled render,
                                   texels; crop_width 0 = no crop */
  int threads;                  /* 0..BB_MAX_THREADS, 0 = all cores; results
                                   are identical */
  int view;                     /* 1: an orthographic camera at view_azimuth,
                                   view_elevation looks at the surface (the
                                   texture tiling on for ever); 0 (default):
                                   straight down, texel for pixel */
  double view_azimuth;          /* degrees, as the light's (default 270: from the
                                   bottom of the image, which then recedes up
                                   the picture) */
  double view_elevation;        /* degrees, 1..90 (default 30) */
  int relief;                   /* 1: parallax occlusion mapping of
                                   relief_height as shaders/ssbump_relief.glsl
                                   does it: each pixel's view ray is followed
                                   into the relief and the maps are read where
                                   it meets it; needs view */
  const bb_image *relief_height; /* h in [0, 1] in channel 0, the maps' size:
                                   the bake's filtered height. Not owned */
  double relief_depth;          /* texels of relief per unit of h, > 0: the
                                   bake's height_scale (default 0: must be set
                                   with relief) */
} bb_render_options;

/* What a render lit, for its provenance. */
typedef struct bb_render_sources {
  const char *height;   /* the height file baked for it, or NULL: maps read */
  const char *maps[BB_MAP_KIND_COUNT]; /* the map files read, by kind; NULL when not */
  int maps_normal_y_up; /* the normal and bent files were OpenGL-style */
  const char *albedo;   /* the albedo file, or NULL */
  uint64_t albedo_hash; /* the hash of the albedo's pixels, as read */
  int frame, frames;    /* frame of an orbit of frames; frames 0: one picture */
} bb_render_sources;

/* One picture of a panel grid and the label written under it (may be NULL). */
typedef struct bb_panel {
  const bb_image *image; /* 3-channel RGB in [0, 1] (a map as an 8-bit file shows it) */
  const char *label;
} bb_panel;

typedef struct bb_panel_layout {
  int columns;        /* panels per row, >= 1 (default 4) */
  int panel_width;    /* texels; each panel is resampled to this width keeping its
                         aspect; 0 = the widest panel's width (default 0) */
  int gap;            /* texels between panels and around the grid (default 8) */
  int font_size;      /* label height in pixels, 6..512; 0 = a sixteenth of the
                         panel width, 12..48 (default 0). Made smaller, down to 6,
                         until the widest label fits a panel */
  const char *font;   /* font file or name; NULL = look one up (default NULL) */
} bb_panel_layout;

/* The exponent render --compare uses when o->specular_exponent is 0. */
#define BB_COMPARE_SPECULAR_EXPONENT 64.0

/* sheet's options: its grid and its lit panel. */
typedef struct bb_sheet_options {
  bb_panel_layout layout; /* default 4 columns, panels 256 texels wide */
  bb_render_options lit;  /* the lit panel (default: ssbump, light 135, 45) */
} bb_sheet_options;

extern const bb__range bb__range_light_elevation, bb__range_view_elevation,
    bb__range_colour, bb__range_specular_exponent, bb__range_specular_strength,
    bb__range_tile;

/* bb__render_files_check's estimate without its memory check: *need, the
 * bytes of memory the render of files will take at its peak (0 when a
 * read will refuse a file first, as too large), the file messages name
 * (*named: the output, else the first file read) and what it is ("a 16384
 * x 16384 render", what_cap bytes). */
bb_status bb__render_files_need(const bb_render_sources *files,
                                const bb_bake_options *bake, const bb_render_options *o,
                                int compare, const char *output, bb_depth depth,
                                int *width, int *height, double *need, const char **named,
                                char *what, size_t what_cap, bb_error *err);

/* Once in bumpbake.h, now internal (issue 41): no client of the
 * library calls these; the library, tests, tools and fuzz targets do. */

/* Parses "multiply", "mod2x", "ssbump". */
bb_status bb__albedo_mode_parse(const char *name, bb_albedo_mode *out, bb_error *err);
const char *bb__albedo_mode_name(bb_albedo_mode mode);

/* Parses "ssbump", "normal", "ao", "slope". */
bb_status bb__render_mode_parse(const char *name, bb_render_mode *out, bb_error *err);

/* Unit direction towards a light at azimuth and elevation in degrees, in the
 * tangent frame (+Y down): azimuth 0 = from the right (+x), 90 = from the
 * top of the image (-y), 180 = from the left, 270 = from the bottom,
 * counter-clockwise as seen on screen; elevation 0 = grazing, 90 = overhead.
 * dir = (cos(el) cos(az), -cos(el) sin(az), sin(el)), exact at multiples of
 * 90 degrees. */
void bb__light_direction(double azimuth_degrees, double elevation_degrees, double dir[3]);

/* Renders maps by o into out (allocated: 3 channels, linear values, 1 =
 * white, not clamped), then tiles and crops it as o says. Bit-identical for
 * any thread count. With o->view the picture is the same size (the maps'
 * times the tiles, then cropped), seen by the camera: pixel (i, j) shows
 * the point of the surface's top plane
 *   C + (i - W'/2) R + (j - H'/2) / sin(el) D,   W' x H' the picture,
 * C its middle, D = (cos az, -sin az) the horizontal way to the viewer and
 * R = (D_y, -D_x) (texels; the maps tile), or with o->relief where the
 * view ray from there meets o->relief_height (README "render"), and the maps are
 * read there bilinearly (texel (x, y) at point (x, y), tiling); the
 * specular highlight takes the view direction V instead of (0, 0, 1). View
 * 270, 90 without relief is the plain render. Errors: BB_ERR_ARGUMENT
 * (missing map for the mode, too few channels, maps of different sizes,
 * option out of range: the message says which), BB_ERR_SIZE,
 * BB_ERR_MEMORY. */
bb_status bb__render(const bb_render_maps *maps, const bb_render_options *o, bb_image *out,
                    bb_error *err);

/* The picture a render of maps of width x height makes by o (with compare,
 * bb__render_compare's four-panel grid), worked out from the sizes alone,
 * before anything is read or allocated: *picture_width x *picture_height
 * (the maps' size times o's tiles, then o's crop; may be NULL) and *bytes
 * (may be NULL), the most memory the render takes beyond its maps: the
 * picture as rendered, tiled and cropped (3 floats a texel), and the copy
 * the encoder of output at depth makes of it (output NULL: none, the
 * picture alone). bb__render
 * refuses (BB_ERR_MEMORY) a picture whose estimate is over
 * bb__memory_available before it allocates it. Errors: BB_ERR_SIZE (the
 * tiled picture over BB_MAX_DIMENSION a side or BB_MAX_PIXELS in all),
 * BB_ERR_ARGUMENT (a crop not inside it), each message saying so. */
bb_status bb__render_estimate(int width, int height, const bb_render_options *o, int compare,
                             const char *output, bb_depth depth, int *picture_width,
                             int *picture_height, double *bytes, bb_error *err);

/* "key=value" lines of every option of o that affects pixels (render_mode,
 * light, light_color, lightmap, specular, specular_strength, albedo_mode,
 * tile, crop; view and relief when used), for
 * provenance; malloc'd, the caller frees it. NULL when out of memory. */
char *bb__render_options_describe(const bb_render_options *o);

/* The "key=value" lines a render adds to bb__provenance_format's (as its
 * extra): render_from (height or maps), map_normal_y, map_KIND (file
 * names), albedo and albedo_hash, then bb__render_options_describe's, then
 * frame=F/N for an orbit's frame. malloc'd; NULL when out of memory. */
char *bb__render_provenance(const bb_render_sources *s, const bb_render_options *o);

/* A render of files checked from their headers before any pixel is read,
 * as bakes are: the maps (files->maps) or the height baked first
 * (files->height, with bake, its outputs set) and the albedo
 * (files->albedo, may be NULL); the maps share one size (*width x *height,
 * may be NULL, set as soon as the first header is read); the picture fits
 * (bb__render_estimate, with output and depth); and reading them as
 * floats (for a height, its read and the bake, as bb__bake_checked estimates it),
 * with the picture, fits in bb__memory_available. A file whose header is over the
 * read's limits is left to the read to refuse. Errors: those of
 * bb_image_read_info and bb__render_estimate, BB_ERR_ARGUMENT (maps of two
 * sizes, naming the file), BB_ERR_MEMORY ("OUTPUT: a 32768 x 32768 render
 * needs about 16.3 GiB of memory; 5.4 GiB is available (RLIMIT_AS)"). */
bb_status bb__render_files_check(const bb_render_sources *files, const bb_bake_options *bake,
                                const bb_render_options *o, int compare, const char *output,
                                bb_depth depth, int *width, int *height, bb_error *err);

/* The file of frame `frame` of an orbit of `frames` written to output:
 * OUT_007.png for OUT.png (four digits past 1000 frames). malloc'd; NULL
 * when out of memory. */
char *bb__render_frame_path(const char *output, int frame, int frames);

/* Repeats in nx x ny times (nx, ny >= 1) into out. */
bb_status bb__image_tile(const bb_image *in, int nx, int ny, bb_image *out, bb_error *err);

/* The window (x, y, width, height) of in, which must lie inside it, into out. */
bb_status bb__image_crop(const bb_image *in, int x, int y, int width, int height,
                        bb_image *out, bb_error *err);

/* Resamples in to width x height by area averaging (each output texel is the
 * mean of the input area it covers; enlarging repeats texels). */
bb_status bb__image_resample(const bb_image *in, int width, int height, bb_image *out,
                            bb_error *err);

/* A map as it looks in an 8-bit file, as 3-channel RGB in [0, 1]: signed
 * maps (normals) become 0.5 + 0.5 v, unit maps (v - low) / (high - low);
 * 1- and 2-channel maps become grey (channel 0), others show their first
 * three channels. Values are clamped to [0, 1]. */
bb_status bb__image_to_display(const bb_image *map, bb_range range, float low, float high,
                              bb_image *rgb, bb_error *err);

void bb__panel_layout_init(bb_panel_layout *l);

/* Lays out count panels in a grid on a dark background, each labelled
 * underneath through OpenImageIO's text rendering. Labels need a font: the
 * layout's, else $BUMPBAKE_FONT when set (empty: none), else the first of
 * DejaVu Sans, Liberation Sans, FreeSans, Noto Sans that OpenImageIO finds.
 * With no usable font the grid is drawn without label rows. *labels_drawn
 * (may be NULL) receives 1 when labels were drawn, 0 otherwise. out gets 3
 * channels. */
bb_status bb__panels_compose(const bb_panel *panels, int count, const bb_panel_layout *l,
                            bb_image *out, int *labels_drawn, bb_error *err);

/* The paper's comparison: four renders side by side, labelled "normal-mapped",
 * "ssbump", "ssbump + specular" and "ao" (modes normal, ssbump, ssbump with
 * the specular exponent of o or 64 when o has none, ao), each by o
 * otherwise (o->mode is not used). maps needs normal, ssbump and ao. */
bb_status bb__render_compare(const bb_render_maps *maps, const bb_render_options *o,
                            const bb_panel_layout *l, bb_image *out, int *labels_drawn,
                            bb_error *err);

void bb__sheet_options_init(bb_sheet_options *o);

/* A contact sheet of one bake: height and filtered height (grey, stretched
 * over the height's range), normal, weights, ssbump, ao, bent normal, and
 * the ssbump lit by o->lit; labelled as bb__panels_compose does. height is
 * the bake's input; r a traced bake with normal_y_up = 0 and Half-Life 2's
 * basis (another is BB_ERR_ARGUMENT). */
bb_status bb__sheet_make(const bb_image *height, const bb_bake_result *r,
                        const bb_sheet_options *o, bb_image *out, int *labels_drawn,
                        bb_error *err);

/* Once in bumpbake.h beside the functions that stay public there. */
/* The name bb__render_mode_parse accepts; "unknown" for other values. */
const char *bb__render_mode_name(bb_render_mode mode);
unsigned bb__render_mode_needs(bb_render_mode mode);

/* render's defaults: ssbump, the light at 135, 45 (once public: a client
 * reads them by name from a new render command, bb_command_value). */
void bb__render_options_init(bb_render_options *o);

#endif /* BB_RENDER_INTERNAL_H */
