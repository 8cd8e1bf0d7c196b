# tools/rename_internal.sed: the exports no client used, renamed bb__ (issue 41).
# Re-apply to a branch: sed -i -E -f tools/rename_internal.sed FILES (src include tests tools fuzz docs python).
# Nine already had a bb__ twin with a threads argument; the old wrapper takes a name of its own.
s/\bbb_addressing_name\b/bb__addressing_name/g
s/\bbb_albedo_mode_name\b/bb__albedo_mode_name/g
s/\bbb_albedo_mode_parse\b/bb__albedo_mode_parse/g
s/\bbb_animation_abort\b/bb__animation_abort/g
s/\bbb_animation_add_frame\b/bb__animation_add_frame/g
s/\bbb_animation_close\b/bb__animation_close/g
s/\bbb_animation_open\b/bb__animation_open/g
s/\bbb_axis_frame\b/bb__axis_frame/g
s/\bbb_axis_parse\b/bb__axis_parse/g
s/\bbb_bake_options_check\b/bb__bake_options_check/g
s/\bbb_bake_rayset_id\b/bb__bake_rayset_id/g
s/\bbb_basis_dirs\b/bb__basis_dirs/g
s/\bbb_basis_init\b/bb__basis_init/g
s/\bbb_basis_is_hl2\b/bb__basis_is_hl2/g
s/\bbb_basis_load\b/bb__basis_load/g
s/\bbb_basis_map_check\b/bb__basis_map_check/g
s/\bbb_basis_parse\b/bb__basis_parse/g
s/\bbb_basis_read_text\b/bb__basis_read_text/g
s/\bbb_basis_vector\b/bb__basis_vector/g
s/\bbb_channel_name\b/bb__channel_name/g
s/\bbb_command_has_job\b/bb__command_has_job/g
s/\bbb_command_info_nearest\b/bb__command_info_nearest/g
s/\bbb_compare_images\b/bb__compare_images/g
s/\bbb_compare_judge\b/bb__compare_judge/g
s/\bbb_compare_limits_check\b/bb__compare_limits_check/g
s/\bbb_compare_limits_init\b/bb__compare_limits_init/g
s/\bbb_depth_like_input\b/bb__depth_like_input/g
s/\bbb_depth_name\b/bb__depth_name/g
s/\bbb_derive_ao\b/bb__derive_ao_all_cores/g
s/\bbb_derive_bent\b/bb__derive_bent_all_cores/g
s/\bbb_derive_ssbump\b/bb__derive_ssbump_all_cores/g
s/\bbb_directory_create\b/bb__directory_create/g
s/\bbb_file_write\b/bb__file_write/g
s/\bbb_image_crop\b/bb__image_crop/g
s/\bbb_image_frame_count\b/bb__image_frame_count/g
s/\bbb_image_hash\b/bb__image_hash/g
s/\bbb_image_resample\b/bb__image_resample/g
s/\bbb_image_tile\b/bb__image_tile/g
s/\bbb_image_to_display\b/bb__image_to_display/g
s/\bbb_image_write\b/bb__image_write/g
s/\bbb_image_write_mips\b/bb__image_write_mips/g
s/\bbb_image_write_mips_staged\b/bb__image_write_mips_staged_all_cores/g
s/\bbb_image_write_staged\b/bb__image_write_staged_all_cores/g
s/\bbb_json_quoted\b/bb__json_quoted/g
s/\bbb_light_direction\b/bb__light_direction/g
s/\bbb_map_kind_name\b/bb__map_kind_name/g
s/\bbb_map_kind_parse\b/bb__map_kind_parse/g
s/\bbb_map_kind_records\b/bb__map_kind_records/g
s/\bbb_memory_available\b/bb__memory_available/g
s/\bbb_mesh_alloc\b/bb__mesh_alloc/g
s/\bbb_mesh_free\b/bb__mesh_free/g
s/\bbb_mesh_hash\b/bb__mesh_hash/g
s/\bbb_mesh_load\b/bb__mesh_load/g
s/\bbb_mesh_load_noted\b/bb__mesh_load_noted/g
s/\bbb_mesh_write\b/bb__mesh_write/g
s/\bbb_normal_filter_parse\b/bb__normal_filter_parse/g
s/\bbb_normal_y_name\b/bb__normal_y_name/g
s/\bbb_normals_compute\b/bb__normals_compute_all_cores/g
s/\bbb_option_choices\b/bb__option_choices/g
s/\bbb_panel_layout_init\b/bb__panel_layout_init/g
s/\bbb_panels_compose\b/bb__panels_compose/g
s/\bbb_path_is_readable_format\b/bb__path_is_readable_format/g
s/\bbb_path_is_texture_format\b/bb__path_is_texture_format/g
s/\bbb_path_is_writable_format\b/bb__path_is_writable_format/g
s/\bbb_path_max_channels\b/bb__path_max_channels/g
s/\bbb_path_supports_depth\b/bb__path_supports_depth/g
s/\bbb_path_supports_mips\b/bb__path_supports_mips/g
s/\bbb_program_image_path\b/bb__program_image_path/g
s/\bbb_program_images\b/bb__program_images/g
s/\bbb_provenance_diff\b/bb__provenance_diff/g
s/\bbb_provenance_value\b/bb__provenance_value/g
s/\bbb_pyramid_build\b/bb__pyramid_build_all_cores/g
s/\bbb_rayset_make\b/bb__rayset_new/g
s/\bbb_render\b/bb__render/g
s/\bbb_render_compare\b/bb__render_compare/g
s/\bbb_render_estimate\b/bb__render_estimate/g
s/\bbb_render_files_check\b/bb__render_files_check/g
s/\bbb_render_frame_path\b/bb__render_frame_path/g
s/\bbb_render_mode_name\b/bb__render_mode_name/g
s/\bbb_render_mode_needs\b/bb__render_mode_needs/g
s/\bbb_render_mode_parse\b/bb__render_mode_parse/g
s/\bbb_render_options_describe\b/bb__render_options_describe/g
s/\bbb_render_provenance\b/bb__render_provenance/g
s/\bbb_renderbump_describe\b/bb__renderbump_describe/g
s/\bbb_renderbump_flat\b/bb__renderbump_flat/g
s/\bbb_renderbump_options_init\b/bb__renderbump_options_init/g
s/\bbb_renderbump_write\b/bb__renderbump_write/g
s/\bbb_same_file\b/bb__same_file/g
s/\bbb_sheet_make\b/bb__sheet_make/g
s/\bbb_sheet_options_init\b/bb__sheet_options_init/g
s/\bbb_slices_for_rays\b/bb__slices_for_rays/g
s/\bbb_slope_decode\b/bb__slope_decode/g
s/\bbb_slope_encode\b/bb__slope_encode/g
s/\bbb_slope_light\b/bb__slope_light/g
s/\bbb_slope_map\b/bb__slope_map/g
s/\bbb_slope_table\b/bb__slope_table/g
s/\bbb_smooth_bilateral\b/bb__smooth_bilateral_all_cores/g
s/\bbb_smooth_options_init\b/bb__smooth_options_init/g
s/\bbb_staged_file_commit\b/bb__staged_file_commit/g
s/\bbb_staged_file_discard\b/bb__staged_file_discard/g
s/\bbb_staged_file_path\b/bb__staged_file_path/g
s/\bbb_staged_files_commit\b/bb__staged_files_commit/g
s/\bbb_tempfiles_remove\b/bb__tempfiles_remove/g
s/\bbb_texture_check\b/bb__texture_check/g
s/\bbb_texture_format_name\b/bb__texture_format_name/g
s/\bbb_texture_options_for\b/bb__texture_options_for/g
s/\bbb_texture_provenance\b/bb__texture_provenance/g
s/\bbb_texture_write\b/bb__texture_write/g
s/\bbb_trace_occlusion\b/bb__trace_occlusion/g
s/\bbb_trace_options_init\b/bb__trace_options_init/g
s/\bbb_utf8_sequence\b/bb__utf8_sequence/g
s/\bbb_vmt_text\b/bb__vmt_text/g
# The JSON writer leaves the ABI (src/core/json.h; the CLI compiles json.c into itself).
s/\bbb_json\b/bb__json/g
s/\bbb_json_(open|close|string|number|int|bool)\b/bb__json_\1/g
s/\bbb_job_prefix_path\b/bb__job_prefix_path/g
# Texture header readers and the provenance classifier: only the library and tests call them (info returns their data).
s/\bbb_vtf_read_info\b/bb__vtf_read_info/g
s/\bbb_vtf_info_free\b/bb__vtf_info_free/g
s/\bbb_dds_read_info\b/bb__dds_read_info/g
s/\bbb_provenance_classify\b/bb__provenance_classify/g
# enum parsers and names a client reads through the option rows (bb_option_parse,
# bb_option_word), and the exports no client used.
s/\bbb_channel_parse\b/bb__channel_parse/g
s/\bbb_depth_parse\b/bb__depth_parse/g
s/\bbb_normal_y_parse\b/bb__normal_y_parse/g
s/\bbb_texture_format_parse\b/bb__texture_format_parse/g
s/\bbb_vtf_flags_parse\b/bb__vtf_flags_parse/g
s/\bbb_vtf_version_parse\b/bb__vtf_version_parse/g
s/\bbb_normal_filter_name\b/bb__normal_filter_name/g
s/\bbb_axis_name\b/bb__axis_name/g
s/\bbb_height_channel\b/bb__height_channel/g
s/\bbb_image_read_mip\b/bb__image_read_mip/g
s/\bbb_job_options_init\b/bb__job_options_init/g
s/\bbb_output_check\b/bb__output_check/g
s/\bbb_valve_detail\b/bb__valve_detail/g
s/\bbb_valve_pack\b/bb__valve_pack/g
s/\bbb_command_input_count\b/bb__command_input_count/g
s/\bbb_valve_options_init\b/bb__valve_options_init/g
# the DOOM 3 program family, run by a client through its command (bb_command_program).
s/\bbb_program_parse\b/bb__program_parse/g
s/\bbb_program_free\b/bb__program_free/g
s/\bbb_program_options_init\b/bb__program_options_init/g
s/\bbb_program_run\b/bb__program_run/g
s/\bbb_program_options\b/bb__program_options/g
s/\bbb_program\b/bb__program/g
s/\bbb_image_loader\b/bb__image_loader/g
# defaults and lookups a client reads from the descriptions (a new command's options, bb_command_info_get's NULL, bb_command_option's short_name).
s/\bbb_render_options_init\b/bb__render_options_init/g
s/\bbb_command_count\b/bb__command_count/g
s/\bbb_option_find_short\b/bb__option_find_short/g
# the reports' words through one string-keyed call (bb_report_word).
s/\bbb_job_outcome_name\b/bb__job_outcome_name/g
s/\bbb_check_status_name\b/bb__check_status_name/g
# the map operators of normal2ssbump, ssbump2normal and combine, run by a client through their commands (bb_command_map).
s/\bbb_combine_blend\b/bb__combine_blend/g
s/\bbb_combine_detail\b/bb__combine_detail/g
s/\bbb_combine_brightness\b/bb__combine_brightness/g
s/\bbb_map_flat_texel\b/bb__map_flat_texel/g
s/\bbb_derive_weights\b/bb__derive_weights_all_cores/g
s/\bbb_ssbump_to_normal\b/bb__ssbump_to_normal/g
s/\bbb_image_flip_green\b/bb__image_flip_green/g
# a command's options struct leaves the ABI (clients read options by name,
# or the bake's settings through bb_command_job_options).
s/\bbb_command_options_of\b/bb__command_options_of/g
# the bake's stage calls only Python and the install check used; both bake
# through the command now (bb_command_bake).
s/\bbb_bake_result_image\b/bb__bake_result_image/g
s/\bbb_bake_context_bake\b/bb__bake_context_bake/g
s/\bbb_bake\b/bb__bake_checked/g
s/\bbb_bake_options_init\b/bb__bake_options_init/g
# a job planned from the caller's own options, and the line such a job
# records: serve, their last client, plans through its bake command
# (bb_command_plan) now.
s/\bbb_job_plan\b/bb__job_plan_options/g
s/\bbb_job_command_text\b/bb__job_command_text/g
# what a split trace traces, built of a height and bake options: Python's
# workers build it of the handed-over command now (bb_command_trace_input).
s/\bbb_bake_trace_input\b/bb__bake_trace_input/g
# serve, their last client, reads its write's files (bb_command_map_file)
# and a written report's JSON (bb_command_report_json) through its command:
# the rule for a map's file, the JSON of a report and the path helper under
# them are the library's own.
s/\bbb_job_map_file\b/bb__job_map_file/g
s/\bbb_job_report_json\b/bb__job_report_json/g
s/\bbb_path_with_suffix\b/bb__path_with_suffix/g
# no client reads a bake's or a job's options since serve and Python read
# through their commands: the calls that took or gave them are the
# library's own, and so are the structs (src/bake/bake_internal.h,
# src/job/job_options.h).
s/\bbb_bake_slices\b/bb__bake_slices/g
s/\bbb_height_file_read\b/bb__height_file_read/g
s/\bbb_provenance_format\b/bb__provenance_format/g
s/\bbb_command_job_options\b/bb__command_job_options/g
