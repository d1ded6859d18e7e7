/* test_args.c - every public function of hfvis.h against every invalid argument class, and a
 * failing-allocator sweep over every public function that allocates.
 *
 * INVENTORY (below, the X-macro table HFVIS_INVENTORY) has one row per HFVIS_API function of
 * hfvis.h, in header order:
 *   name     the function without the hfvis_ prefix;
 *   kind     S = returns hfvis_status; V = returns a value that signals invalid input (0, -1,
 *            NaN, NULL, as its documentation says); P = pure helper or void function that
 *            cannot fail (documented; called with its edge inputs to show it does not crash);
 *   alloc    A = allocates through an hfvis_allocator (argument or options->alloc): swept by
 *            failing allocation k = 1, 2, ... until the call succeeds; M = allocates with plain
 *            malloc and has no allocator (the *_save file writers): checked by their I/O
 *            failure paths in a temporary directory; - = allocates nothing;
 *   classes  the invalid-argument classes that apply and are exercised:
 *              N NULL pointer, Z zero size/count, G negative value, O overflowing size or
 *              documented limit, F NaN or infinity, E unknown enum value, S invalid field of an
 *              options / descriptor struct, R other out-of-range value (stride < width, index
 *              >= count, short buffer, non-increasing sequence, ...);
 *   returns  what hfvis.h documents for those inputs.
 * Each args_<name>() first makes one valid call (it must succeed: the invalid calls then fail
 * for the reason they test), then one call per invalid input. Every output lives in one arena
 * filled with a sentinel byte before each call; after a failing call the arena must be
 * unchanged (outputs untouched). The test checks that the classes each function exercises are
 * exactly those its row declares, that every row has an args function, that every A row has a
 * sweep entry, and (when run from the repository root) that the rows are exactly the HFVIS_API
 * functions of hfvis.h.
 * POSIX (mkdtemp) is used only for the file functions' temporary directory. */
#define _POSIX_C_SOURCE 200809L
#include "hfvis.h"
#include "test.h"

#include "test_dir.h"
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

/* ========================================================================================== */
/* Inventory: every HFVIS_API function of hfvis.h, in header order                            */
/* ========================================================================================== */
/*  X(name, kind, alloc, classes, returns) - see the top of the file for the columns.           */
#define HFVIS_INVENTORY(X) \
    X(status_string, V, -, "E", "an HFVIS_ERR_UNKNOWN string, never NULL") \
    X(free, V, -, "N", "no-op for NULL") \
    X(crc32, V, -, "N", "the crc unchanged for NULL with n = 0") \
    X(image_info_read, S, -, "NZO", "INVALID_ARGUMENT FORMAT LIMIT") \
    X(image_decode, S, -, "NZOR", "INVALID_ARGUMENT FORMAT LIMIT BUFFER_TOO_SMALL") \
    X(pfm_encode_size, V, -, "ZGOR", "0") \
    X(pgm_encode_size, V, -, "ZGR", "0") \
    X(pfm_encode, S, -, "NZGOR", "INVALID_ARGUMENT BUFFER_TOO_SMALL") \
    X(pgm_encode, S, -, "NZGOFR", "INVALID_ARGUMENT BUFFER_TOO_SMALL") \
    X(write_options_default, P, -, "", "cannot fail") \
    X(write_file, S, M, "NZR", "INVALID_ARGUMENT IO") \
    X(write_begin, S, M, "NZR", "INVALID_ARGUMENT IO") \
    X(write_end, S, -, "NR", "INVALID_ARGUMENT IO") \
    X(image_load, S, A, "NR", "INVALID_ARGUMENT IO") \
    X(pfm_save, S, M, "NZGR", "INVALID_ARGUMENT IO") \
    X(pgm_save, S, M, "NZGFR", "INVALID_ARGUMENT IO") \
    X(pgm_range_encode_size, V, -, "ZGFR", "0") \
    X(pgm_range_encode, S, -, "NZGFR", "INVALID_ARGUMENT BUFFER_TOO_SMALL") \
    X(pgm_range_save, S, M, "NZGFR", "INVALID_ARGUMENT IO") \
    X(pgm_range_read, S, -, "NZOR", "INVALID_ARGUMENT FORMAT LIMIT") \
    X(pgm_range_decode, S, -, "NZOR", "INVALID_ARGUMENT FORMAT LIMIT BUFFER_TOO_SMALL") \
    X(field_height, V, -, "NFES", "NaN") \
    X(field_generate, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(grid_sample, V, -, "NZF", "NaN") \
    X(normals_compute, S, -, "NZGOFR", "INVALID_ARGUMENT") \
    X(exact_grid_compute, S, -, "NZGOFR", "INVALID_ARGUMENT") \
    X(exact_grid_rows, S, -, "NZGOFR", "INVALID_ARGUMENT") \
    X(lattice_init, S, -, "NZGOF", "INVALID_ARGUMENT LIMIT") \
    X(lattice_nodes, V, -, "N", "0") \
    X(lattice_line, V, -, "NR", "0") \
    X(sweep_options_default, P, -, "", "cannot fail") \
    X(tile_halo, V, -, "ZGFE", "-1") \
    X(line_horizons, S, -, "NGFR", "INVALID_ARGUMENT") \
    X(line_horizons_naive, S, -, "NGFR", "INVALID_ARGUMENT") \
    X(horizon_lattice, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(horizon_lattice_naive, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(horizon_direction, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(horizon_map, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(march_options_default, P, -, "", "cannot fail") \
    X(horizon_reference, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(horizon_reference_fn, S, -, "NZGFES", "INVALID_ARGUMENT") \
    X(openness_options_default, P, -, "", "cannot fail") \
    X(openness, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(sweep_azimuths, S, A, "NZGES", "INVALID_ARGUMENT") \
    X(horizon_exact_naive, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(sector_weight, V, -, "ZGF", "NaN") \
    X(sky_light, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(sky_light_from_map, S, A, "NZGOFR", "INVALID_ARGUMENT") \
    X(sky_view_factor, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(sky_view_factor_from_map, S, -, "NZGOFR", "INVALID_ARGUMENT") \
    X(sun_visibility, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(env_options_default, P, -, "", "cannot fail") \
    X(env_table_floats, V, -, "NZGOES", "0") \
    X(env_table_build, S, -, "NZGOFES", "INVALID_ARGUMENT") \
    X(env_light, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(env_light_from_map, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(hemisphere_options_default, P, -, "", "cannot fail") \
    X(light_reference, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(tree_options_default, P, -, "", "cannot fail") \
    X(hull_tree_size, V, -, "ZG", "0") \
    X(hull_tree_init, S, -, "NZGOESR", "INVALID_ARGUMENT BUFFER_TOO_SMALL") \
    X(hull_tree_reset, V, -, "N", "no-op for NULL") \
    X(hull_tree_push, S, -, "NOFR", "INVALID_ARGUMENT LIMIT") \
    X(hull_tree_horizons, V, -, "NG", "-1") \
    X(hull_tree_count, V, -, "N", "0") \
    X(hull_tree_iterations, V, -, "N", "0") \
    X(line_visible_from_horizons, V, -, "NG", "-1") \
    X(line_visible_naive, V, -, "NG", "-1") \
    X(line_local_horizons_naive, V, -, "NG", "-1") \
    X(intervisibility, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(visibility_count, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(visibility_count_naive, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(indirect_light, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(indirect_light_naive, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(terrain_gi, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(direct_light, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(spa, S, -, "NGFR", "INVALID_ARGUMENT") \
    X(rsun_sun_position, S, -, "NZGFR", "INVALID_ARGUMENT") \
    X(esra_clear_sky, S, -, "NGFR", "INVALID_ARGUMENT") \
    X(solar_input_default, P, -, "", "cannot fail") \
    X(solar_options_default, P, -, "", "cannot fail") \
    X(solar_map_options, P, -, "", "cannot fail") \
    X(solar_map_directions, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(solar_band_count, V, -, "NZE", "-1") \
    X(solar_irradiation, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(solar_irradiation_reference, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(viewshed_options_default, P, -, "", "cannot fail") \
    X(viewshed, S, -, "NZGOFSR", "INVALID_ARGUMENT") \
    X(viewshed_reference, S, -, "NZGOFSR", "INVALID_ARGUMENT") \
    X(sh_eval, S, -, "NZF", "INVALID_ARGUMENT") \
    X(sh_rotate_z, S, -, "NF", "INVALID_ARGUMENT") \
    X(sh_dot, S, -, "N", "INVALID_ARGUMENT") \
    X(sh_product_tensor, S, -, "N", "INVALID_ARGUMENT") \
    X(sh_product, S, -, "N", "INVALID_ARGUMENT") \
    X(sh_convolve_zh, S, -, "NF", "INVALID_ARGUMENT") \
    X(sh_from_zh, S, -, "NZF", "INVALID_ARGUMENT") \
    X(sh_shade_zh, S, -, "NZF", "INVALID_ARGUMENT") \
    X(zh_diffuse, S, -, "N", "INVALID_ARGUMENT") \
    X(zh_phong, S, -, "NZGF", "INVALID_ARGUMENT") \
    X(zh_cap, S, -, "NGFR", "INVALID_ARGUMENT") \
    X(sh_project_env, S, -, "NZGOS", "INVALID_ARGUMENT") \
    X(nlp_eval, S, -, "NGFR", "INVALID_ARGUMENT") \
    X(nlp_occlusion, S, -, "NF", "INVALID_ARGUMENT") \
    X(nlp_visibility, S, -, "NF", "INVALID_ARGUMENT") \
    X(nlp_radiance, S, -, "NGFR", "INVALID_ARGUMENT") \
    X(nlp_reconstruct, S, -, "NF", "INVALID_ARGUMENT") \
    X(ns_wedge_columns, V, -, "E", "0") \
    X(ns_wedge_matrix, S, -, "NZGFER", "INVALID_ARGUMENT") \
    X(ns_wedges_full, S, -, "NZGFE", "INVALID_ARGUMENT") \
    X(ns_wedges_partial, S, -, "NGFER", "INVALID_ARGUMENT") \
    X(ns_wedges_to_sh, S, -, "NZGE", "INVALID_ARGUMENT") \
    X(ns_min_blocking_angle, S, -, "NZFE", "INVALID_ARGUMENT") \
    X(ns_gi_options_default, P, -, "", "cannot fail") \
    X(ns_gi_options_resolve, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(ns_gi, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(ns_gi_scratch_size, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(ns_bspline_max, S, -, "NGF", "INVALID_ARGUMENT") \
    X(ns_sample_matrices, S, -, "NZE", "INVALID_ARGUMENT") \
    X(direction_sums, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(partial_encode_size, V, -, "NZGOSR", "0") \
    X(partial_encode, S, -, "NZGOSR", "INVALID_ARGUMENT BUFFER_TOO_SMALL") \
    X(partial_decode, S, A, "NZGOFER", "INVALID_ARGUMENT FORMAT LIMIT") \
    X(partial_free, V, -, "N", "no-op for NULL") \
    X(partial_save, S, M, "NZGOSR", "INVALID_ARGUMENT IO") \
    X(partial_load, S, A, "NZOR", "INVALID_ARGUMENT FORMAT LIMIT IO") \
    X(camera_check, S, -, "NZGOFER", "INVALID_ARGUMENT LIMIT") \
    X(camera_perspective, S, -, "NZGOFR", "INVALID_ARGUMENT LIMIT") \
    X(camera_orthographic, S, -, "NZGOF", "INVALID_ARGUMENT LIMIT") \
    X(camera_from_view, S, -, "NZGOFSR", "INVALID_ARGUMENT LIMIT") \
    X(camera_unproject, S, -, "NZGOFER", "INVALID_ARGUMENT") \
    X(camera_project, S, -, "NZGOFER", "INVALID_ARGUMENT") \
    X(depth_linear, V, -, "ZFER", "NaN; +(double)INFINITY for a non-finite depth") \
    X(depth_hardware, V, -, "GFER", "NaN") \
    X(depth_linearize, S, -, "NZGOFER", "INVALID_ARGUMENT") \
    X(camera_from_matrix, S, -, "NZGOFER", "INVALID_ARGUMENT LIMIT") \
    X(depth_normals, S, -, "NZGOFER", "INVALID_ARGUMENT") \
    X(camera_line_plane, S, -, "NZGOFER", "INVALID_ARGUMENT") \
    X(falloff_check, S, -, "NZGFE", "INVALID_ARGUMENT") \
    X(falloff_eval, V, -, "FE", "NaN") \
    X(falloff_support, V, -, "GE", "NaN") \
    X(ssao_directions_uniform, S, -, "NZGOFR", "INVALID_ARGUMENT") \
    X(ssao_directions_box, S, -, "NZGOFR", "INVALID_ARGUMENT") \
    X(ssao_lattice_init, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(ssao_lattice_lines, S, -, "NZGOFER", "INVALID_ARGUMENT") \
    X(ssao_lattice_nearest, V, -, "NF", "0") \
    X(lsao_options_default, P, -, "", "cannot fail") \
    X(lsao_options_resolve, S, -, "NGOFES", "INVALID_ARGUMENT") \
    X(lsao_directions, S, -, "NGOFES", "INVALID_ARGUMENT") \
    X(lsao_line, S, -, "NGOFESR", "INVALID_ARGUMENT") \
    X(lsao_line_naive, S, -, "NGOFESR", "INVALID_ARGUMENT") \
    X(lsao_direction, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(lsao_direction_naive, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(lsao_gather, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(lsao, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(hbao_options_default, P, -, "", "cannot fail") \
    X(hbao_options_resolve, S, -, "NGOFES", "INVALID_ARGUMENT") \
    X(hbao, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(ssao_rt_options_default, P, -, "", "cannot fail") \
    X(ssao_rt_options_resolve, S, -, "NGOFES", "INVALID_ARGUMENT") \
    X(ssao_reference, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(ssao_scene_render, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(ffao_options_default, P, -, "", "cannot fail") \
    X(ffao_options_resolve, S, -, "NGOFESR", "INVALID_ARGUMENT") \
    X(ffao_slab_integral, V, -, "ZOFE", "NaN") \
    X(ffao_slab_rho1, V, -, "F", "NaN") \
    X(ffao_table_build, S, A, "NZGOFER", "INVALID_ARGUMENT") \
    X(ffao_table_free, V, -, "N", "no-op for NULL") \
    X(ffao_table_lookup, V, -, "NFS", "NaN") \
    X(ffao_virtual_point, V, -, "N", "no-op for NULL h") \
    X(ffao_sector_weight, V, -, "NFR", "NaN") \
    X(ffao_slice, S, -, "NGOFESR", "INVALID_ARGUMENT") \
    X(ffao, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(ssao_mipmap, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(ssao_bilateral_blur, S, -, "NZGOFR", "INVALID_ARGUMENT") \
    X(ssao_error, S, -, "NZGOFR", "INVALID_ARGUMENT") \
    X(mesh_free, V, -, "N", "no-op for NULL") \
    X(mat4_multiply, P, -, "", "cannot fail") \
    X(mat4_invert, S, -, "NZF", "INVALID_ARGUMENT") \
    X(mat4_look_at, S, -, "NZFR", "INVALID_ARGUMENT") \
    X(mat4_perspective, S, -, "NZGFR", "INVALID_ARGUMENT") \
    X(mat4_ortho, S, -, "NFR", "INVALID_ARGUMENT") \
    X(view_perspective, S, -, "NZGFR", "INVALID_ARGUMENT") \
    X(view_orthographic, S, -, "NZGFR", "INVALID_ARGUMENT") \
    X(depth_to_eye_z, P, -, "", "cannot fail") \
    X(eye_z_to_depth, P, -, "", "cannot fail") \
    X(volume_grid_fit, S, -, "NZGOFR", "INVALID_ARGUMENT LIMIT") \
    X(volume_floats, V, -, "NZGO", "0") \
    X(volume_init, S, -, "NZGOFE", "INVALID_ARGUMENT") \
    X(volume_clear, V, -, "N", "no-op for NULL vol or data") \
    X(volume_write, S, -, "NZGOFER", "INVALID_ARGUMENT") \
    X(volume_merge, S, -, "NZER", "INVALID_ARGUMENT") \
    X(mesh_box, S, A, "NZFR", "INVALID_ARGUMENT") \
    X(mesh_uv_sphere, S, A, "NZGOFR", "INVALID_ARGUMENT LIMIT") \
    X(mesh_icosphere, S, A, "NZGOF", "INVALID_ARGUMENT") \
    X(mesh_torus, S, A, "NZGOFR", "INVALID_ARGUMENT LIMIT") \
    X(mesh_torus_knot, S, A, "NZGOFR", "INVALID_ARGUMENT LIMIT") \
    X(mesh_from_grid, S, A, "NZGOFR", "INVALID_ARGUMENT LIMIT") \
    X(mesh_room, S, A, "N", "INVALID_ARGUMENT") \
    X(mesh_teapot, S, A, "NZGO", "INVALID_ARGUMENT LIMIT") \
    X(mesh_bounds, S, -, "NZOFR", "INVALID_ARGUMENT") \
    X(obj_decode, S, A, "NZFR", "INVALID_ARGUMENT FORMAT") \
    X(obj_encode_size, V, -, "NOR", "0") \
    X(obj_encode, S, -, "NZOFR", "INVALID_ARGUMENT BUFFER_TOO_SMALL") \
    X(mesh_load, S, A, "NR", "INVALID_ARGUMENT IO") \
    X(mesh_save, S, M, "NOFR", "INVALID_ARGUMENT IO") \
    X(raster_options_default, P, -, "", "cannot fail") \
    X(rasterize, S, A, "NZGOFESR", "INVALID_ARGUMENT LIMIT") \
    X(rasterize_reference, S, -, "NZGOFESR", "INVALID_ARGUMENT LIMIT") \
    X(ray_triangle, S, -, "NZGFER", "INVALID_ARGUMENT") \
    X(bvh_options_default, P, -, "", "cannot fail") \
    X(bvh_build, S, A, "NGOFSR", "INVALID_ARGUMENT LIMIT") \
    X(bvh_free, V, -, "N", "no-op for NULL") \
    X(bvh_intersect, S, -, "NZGOFER", "INVALID_ARGUMENT") \
    X(bvh_closest_hit, S, -, "NZGOFER", "INVALID_ARGUMENT") \
    X(bvh_any_hit, S, -, "NZGOFER", "INVALID_ARGUMENT") \
    X(ray_intersect_naive, S, -, "NZGFER", "INVALID_ARGUMENT") \
    X(ray_closest_naive, S, -, "NZGFER", "INVALID_ARGUMENT") \
    X(ray_any_naive, S, -, "NZGFER", "INVALID_ARGUMENT") \
    X(voxelize_options_default, P, -, "", "cannot fail") \
    X(gs_max_slices, V, -, "ZGR", "0") \
    X(voxelize_surface, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(voxelize_surface_reference, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(voxelize_occupancy, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(voxel_fragment_occupancy, P, -, "", "cannot fail") \
    X(voxel_fragment_normal_occupancy, P, -, "", "cannot fail") \
    X(voxel_attribute_channel, V, -, "ER", "-1") \
    X(voxel_fragment_attributes, V, -, "N", "user NULL: occupancy only") \
    X(binary_voxel_options_default, P, -, "", "cannot fail") \
    X(triangle_box_overlap, P, -, "", "cannot fail") \
    X(voxelize_conservative, S, A, "NZGOFR", "INVALID_ARGUMENT") \
    X(voxelize_conservative_reference, S, -, "NZGOFR", "INVALID_ARGUMENT") \
    X(voxelize_solid, S, A, "NZGOFER", "INVALID_ARGUMENT FORMAT") \
    X(voxelize_solid_reference, S, -, "NZGOFER", "INVALID_ARGUMENT") \
    X(mesh_is_watertight, S, A, "NOFR", "INVALID_ARGUMENT") \
    X(bitmask_words, V, -, "NZF", "0") \
    X(voxelize_bitmask, S, -, "NZGOFR", "INVALID_ARGUMENT") \
    X(bitmask_to_occupancy, S, -, "NZGOF", "INVALID_ARGUMENT") \
    X(binvox_encode_size, V, -, "NZO", "0") \
    X(binvox_encode, S, -, "NZGOFR", "INVALID_ARGUMENT LIMIT BUFFER_TOO_SMALL") \
    X(binvox_decode, S, A, "NZOR", "INVALID_ARGUMENT FORMAT LIMIT") \
    X(binvox_save, S, M, "NZR", "INVALID_ARGUMENT IO") \
    X(binvox_load, S, A, "NR", "INVALID_ARGUMENT IO") \
    X(voxels_raw_save, S, M, "NZGOFR", "INVALID_ARGUMENT IO") \
    X(iv_options_default, P, -, "", "cannot fail") \
    X(iv_bias_half_diagonal, V, -, "NZF", "NaN") \
    X(iv_bias, S, -, "NZGOFES", "INVALID_ARGUMENT") \
    X(iv_classify, S, -, "NZGOF", "INVALID_ARGUMENT") \
    X(iv_classify_voxel, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(iv_cleanup, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(iv_inject, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(iv_update, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(iv_single_pass, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(iv_replace_nonempty, S, -, "NZGOSR", "INVALID_ARGUMENT") \
    X(iv_occupancy, S, -, "NZGR", "INVALID_ARGUMENT") \
    X(point_triangle_distance, V, -, "N", "NaN") \
    X(distance_options_default, P, -, "", "cannot fail") \
    X(voxel_distance_metrics, S, A, "NZGOFR", "INVALID_ARGUMENT") \
    X(voxel_distance_metrics_naive, S, A, "NZGOFR", "INVALID_ARGUMENT") \
    X(visfield_position_count, V, -, "ZGO", "0") \
    X(visfield_position, S, -, "NZOR", "INVALID_ARGUMENT") \
    X(visfield_nearest_position, S, -, "NZGOF", "INVALID_ARGUMENT") \
    X(visfield_nearest_position_naive, S, -, "NZGOF", "INVALID_ARGUMENT") \
    X(visfield_frame, P, -, "", "cannot fail") \
    X(concentric_square_to_disk, P, -, "", "cannot fail") \
    X(concentric_disk_to_square, P, -, "", "cannot fail") \
    X(dirmap_to_local, S, -, "NZGOER", "INVALID_ARGUMENT") \
    X(dirmap_from_local, S, -, "NZOFER", "INVALID_ARGUMENT") \
    X(visfield_size, V, -, "ZGOE", "0") \
    X(visfield_bounding_sphere, S, -, "NZOFR", "INVALID_ARGUMENT") \
    X(visfield_build_options_default, P, -, "", "cannot fail") \
    X(visfield_build, S, A, "NZOFESR", "INVALID_ARGUMENT BUFFER_TOO_SMALL") \
    X(visfield_build_reference, S, -, "NZOFER", "INVALID_ARGUMENT BUFFER_TOO_SMALL") \
    X(visfield_texel, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(visfield_query, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(visfield_query_reference, S, -, "NZGFSR", "INVALID_ARGUMENT") \
    X(visfield_ao_options_default, P, -, "", "cannot fail") \
    X(visfield_ambient_occlusion, S, A, "NZGOFES", "INVALID_ARGUMENT") \
    X(visfield_ambient_occlusion_reference, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(visfield_shadow_options_default, P, -, "", "cannot fail") \
    X(visfield_soft_shadow, S, A, "NGOFES", "INVALID_ARGUMENT") \
    X(visfield_soft_shadow_reference, S, A, "NGOFES", "INVALID_ARGUMENT") \
    X(visfield_trace, S, -, "NZGOFES", "INVALID_ARGUMENT") \
    X(visfield_trace_reference, S, -, "NZGOFES", "INVALID_ARGUMENT") \
    X(visfield_reflect_options_default, P, -, "", "cannot fail") \
    X(visfield_reflect, S, -, "NZGOFES", "INVALID_ARGUMENT") \
    X(visfield_reflect_reference, S, -, "NZGOFES", "INVALID_ARGUMENT") \
    X(visfield_encode_size, V, -, "NZE", "0") \
    X(visfield_encode, S, -, "NZGOFESR", "INVALID_ARGUMENT BUFFER_TOO_SMALL") \
    X(visfield_decode, S, A, "NZOFER", "INVALID_ARGUMENT FORMAT LIMIT") \
    X(visfield_free, V, -, "N", "no-op for NULL") \
    X(visfield_save, S, M, "NZGOFESR", "INVALID_ARGUMENT IO") \
    X(visfield_load, S, A, "NR", "INVALID_ARGUMENT IO") \
    X(volgi_sh_basis, S, -, "NZF", "INVALID_ARGUMENT") \
    X(volgi_sh_clamped_cosine, S, -, "NZF", "INVALID_ARGUMENT") \
    X(volgi_sh_cone, S, -, "NZGFR", "INVALID_ARGUMENT") \
    X(volgi_options_default, P, -, "", "cannot fail") \
    X(volgi_options_resolve, S, -, "NGOFES", "INVALID_ARGUMENT") \
    X(volgi_inject, S, -, "NZGOFSR", "INVALID_ARGUMENT") \
    X(volgi_propagate_step, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(volgi_propagate_step_reference, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(volgi_propagate, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(volgi_gather, S, -, "NZGOFES", "INVALID_ARGUMENT") \
    X(volgi_direct_irradiance, S, -, "NZGOFESR", "INVALID_ARGUMENT") \
    X(volgi_grid_fit, S, -, "NZOFR", "INVALID_ARGUMENT") \
    X(volgi_voxelize, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(volgi_render, S, A, "NZGOFESR", "INVALID_ARGUMENT LIMIT") \
    X(lk_ray_options_default, P, -, "", "cannot fail") \
    X(lk_rays_build, S, A, "NZGOFES", "INVALID_ARGUMENT") \
    X(lk_rays_custom, S, A, "NZGOFR", "INVALID_ARGUMENT") \
    X(lk_rays_free, V, -, "N", "no-op for NULL") \
    X(lk_mask_words, V, -, "ZGO", "0") \
    X(lk_obscurance, V, -, "NZO", "NaN") \
    X(lk_frame, S, -, "NZGFESR", "INVALID_ARGUMENT") \
    X(lk_lut_bytes, V, -, "ZGOR", "0") \
    X(lk_lut_build, S, A, "NZGOFSR", "INVALID_ARGUMENT") \
    X(lk_lut_free, V, -, "N", "no-op for NULL") \
    X(lk_lut_index, S, -, "NZOFR", "INVALID_ARGUMENT") \
    X(lk_lut_fetch, V, -, "NZF", "NULL") \
    X(lk_plane_mask, S, -, "NZFS", "INVALID_ARGUMENT") \
    X(lk_triangle_mask, S, -, "NZGOFSR", "INVALID_ARGUMENT") \
    X(lk_options_default, P, -, "", "cannot fail") \
    X(lk_options_resolve, S, -, "NZGFESR", "INVALID_ARGUMENT") \
    X(lk_gbuffer_receivers, S, A, "NZGOFER", "INVALID_ARGUMENT LIMIT") \
    X(lk_raster, S, A, "NZGOFESR", "INVALID_ARGUMENT LIMIT") \
    X(lk_bvh, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(lk_reference, S, A, "NZGOFESR", "INVALID_ARGUMENT") \
    X(lk_image, S, A, "NZGOFESR", "INVALID_ARGUMENT LIMIT")

/* ========================================================================================== */
/* Harness: arena, cases, counting allocator                                                  */
/* ========================================================================================== */

/* A few ulps of double arithmetic on unit vectors (the only tolerance: the sanity calls of the
 * pure helpers; every other check is exact). */
#define UNIT_VECTOR_TOL 1e-12

#define INV HFVIS_ERR_INVALID_ARGUMENT
#define LIM HFVIS_ERR_LIMIT
#define SMALL HFVIS_ERR_BUFFER_TOO_SMALL
#define FMT HFVIS_ERR_FORMAT
#define IOE HFVIS_ERR_IO

/* Every output of a call is carved from this arena; a failing call must leave it as filled. */
#define ARENA_BYTES (4u << 20)
#define ARENA_SLACK 256 /* bytes past the last output also checked (writes just past the end) */
#define SENTINEL 0xA5
static unsigned char *arena;
static size_t arena_used, arena_high; /* in use; most ever used */

static void *out_bytes(size_t n)
{
    size_t off = (arena_used + 63) & ~(size_t)63;
    if (off + n + ARENA_SLACK > ARENA_BYTES) {
        fprintf(stderr, "arena exhausted\n");
        exit(2);
    }
    arena_used = off + n;
    if (arena_used > arena_high) arena_high = arena_used;
    memset(arena + off, SENTINEL, n);
    return arena + off;
}
#define AF(n) ((float *)out_bytes((size_t)(n) * sizeof(float)))
#define AD(n) ((double *)out_bytes((size_t)(n) * sizeof(double)))
#define AT(type) ((type *)out_bytes(sizeof(type)))
#define ATN(type, n) ((type *)out_bytes((size_t)(n) * sizeof(type)))

/* What the arena must still hold after a failing call: the sentinel, or (BADP) the state an
 * in/out argument was given before the call. */
static unsigned char *arena_expect;

static void arena_fill_upto(size_t n)
{
    memset(arena, SENTINEL, n);
    memset(arena_expect, SENTINEL, n);
}
static void arena_fill(void) { arena_fill_upto(arena_used + ARENA_SLACK); }
static void arena_snapshot(void) { memcpy(arena_expect, arena, arena_used + ARENA_SLACK); }
static int arena_untouched(void) { return memcmp(arena, arena_expect, arena_used + ARENA_SLACK) == 0; }

/* The function under test, the classes it exercised, counters. */
static const char *cur_name;
static char cur_seen[16];
static int total_cases, class_cases[128];
static unsigned cur_status_mask; /* bit s: status s was expected by some case */
static int cur_value_cases;       /* cases of a value-returning function (BADV) */

static void begin(const char *name)
{
    cur_name = name;
    cur_seen[0] = '\0';
    cur_status_mask = 0;
    cur_value_cases = 0;
    arena_used = 0;
}

static void note_class(char cls)
{
    size_t n = strlen(cur_seen);
    total_cases++;
    class_cases[(unsigned char)cls]++;
    if (!strchr(cur_seen, cls) && n + 1 < sizeof cur_seen) {
        cur_seen[n] = cls;
        cur_seen[n + 1] = '\0';
    }
}

static void case_status(char cls, int want, int got, int line)
{
    note_class(cls);
    if (want >= 0 && want < 32) cur_status_mask |= 1u << want;
    CHECK_EQ_STATUS(got, want);
    CHECK(arena_untouched());
    if (got != want || !arena_untouched()) fprintf(stderr, "  (%s, class %c, line %d)\n", cur_name, cls, line);
}

static void case_value(char cls, int ok, const char *what, int line)
{
    note_class(cls);
    cur_value_cases++;
    CHECK(ok);
    CHECK(arena_untouched());
    if (!ok || !arena_untouched()) fprintf(stderr, "  (%s, class %c, line %d: %s)\n", cur_name, cls, line, what);
}

static void base_status(int got, int line)
{
    CHECK_EQ_STATUS(got, HFVIS_OK);
    if (got != HFVIS_OK) fprintf(stderr, "  (%s: valid baseline call failed, line %d)\n", cur_name, line);
}

/* A valid call (must succeed). */
#define OK(call) do { arena_fill(); base_status((int)(call), __LINE__); } while (0)
/* An invalid call: the documented status, outputs untouched. */
#define BAD(cls, want, call) do { arena_fill(); case_status((cls), (int)(want), (int)(call), __LINE__); } while (0)
/* An invalid call on in/out arguments: poke sets them up in the arena, then the call must fail
 * with want and leave them (and every output) exactly as poke left them. */
#define BADP(cls, want, poke, call) do { arena_fill(); poke; arena_snapshot(); \
    case_status((cls), (int)(want), (int)(call), __LINE__); } while (0)
/* An invalid call of a value-returning function: cond (which makes the call) must hold. */
#define BADV(cls, cond) do { arena_fill(); case_value((cls), (cond) ? 1 : 0, #cond, __LINE__); } while (0)

/* A temporary directory for the file functions. */
static char tmpdir[64];
static char path_buf[400]; /* room for a 255-byte leaf */
static const char *tmp_path(const char *leaf)
{
    snprintf(path_buf, sizeof path_buf, "%s/%s", tmpdir, leaf);
    return path_buf;
}
static const char *bad_dir_path(const char *leaf)
{
    snprintf(path_buf, sizeof path_buf, "%s/no_such_dir/%s", tmpdir, leaf);
    return path_buf;
}

/* ========================================================================================== */
/* Shared valid inputs (built once, in setup())                                               */
/* ========================================================================================== */

#define GW 4
#define GH 3
static float g_z[GW * GH] = {0.0f, 0.5f, 1.0f, 0.25f, 0.75f, 0.1f, 0.3f, 0.9f, 0.2f, 0.6f, 0.4f, 0.8f};
static hfvis_grid g_ok;           /* 4 x 3 height field */
static float g_map[4 * GW * GH];  /* horizon map, K = 4 */
static float g_env_rad[2 * 4];    /* 2 x 4 one-channel environment */
static hfvis_env g_env;
static hfvis_mesh m_box;          /* unit box [0,1]^3, 12 triangles (malloc) */
static hfvis_bvh m_bvh;           /* its BVH (malloc) */
static hfvis_volume_grid vg_ok;   /* 4^3 grid around the box */
static hfvis_camera cam_ok;       /* 8 x 8 perspective, guard 1 */
static float cam_depth[8 * 8];
static float cam_normals[3 * 8 * 8];
static hfvis_view view_ok;        /* 8 x 8 view of the box */
static uint8_t occ_box[4 * 4 * 4];
static hfvis_lk_rays lk_rays;     /* 32 random rays, radius 0.5 (malloc) */
static unsigned char vf_maps[4096];
static hfvis_visfield vf_ok;      /* n = 1, D = 2 field of the box */
static hfvis_visfield_object vf_obj;
static float vg_occ[27], vg_nrm[81], vg_rad[81]; /* 3^3 volgi geometry */
static hfvis_volgi_geometry geo_ok;
static float sh_prop[27 * 12], sh_accum[27 * 12];

static void make_lattice(void);
static hfvis_lk_lut lut_ok;
static hfvis_bvh bad_bvh; /* m_bvh with a wrong triangle count */
static void make_depth_image(void);

static void setup(void)
{
    static const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1};
    static const double eye[3] = {0.5, -2.0, 0.5}, target[3] = {0.5, 0.5, 0.5}, up[3] = {0, 0, 1};
    hfvis_lk_ray_options ro = hfvis_lk_ray_options_default();
    hfvis_ssao_scene sc;
    int i;
    g_ok.z = g_z; g_ok.width = GW; g_ok.height = GH; g_ok.stride = GW; g_ok.cell_size = 1.0;
    for (i = 0; i < 4 * GW * GH; i++) g_map[i] = 0.1f * (float)(i % 7) - 0.2f;
    for (i = 0; i < 8; i++) g_env_rad[i] = 1.0f + 0.1f * (float)i;
    g_env.radiance = g_env_rad; g_env.n_theta = 2; g_env.n_phi = 4; g_env.channels = 1;
    if (hfvis_mesh_box(NULL, lo, hi, &m_box) != HFVIS_OK || hfvis_bvh_build(&m_box, NULL, &m_bvh) != HFVIS_OK)
        exit(2);
    vg_ok.origin[0] = vg_ok.origin[1] = vg_ok.origin[2] = -0.25;
    vg_ok.cell[0] = vg_ok.cell[1] = vg_ok.cell[2] = 0.375;
    vg_ok.dims[0] = vg_ok.dims[1] = vg_ok.dims[2] = 4;
    if (hfvis_camera_perspective(&cam_ok, 8, 8, 1, 1, 1.0) != HFVIS_OK) exit(2);
    memset(&sc, 0, sizeof sc);
    sc.kind = HFVIS_SSAO_SCENE_VGROOVE; sc.base_depth = 4.0; sc.x0 = 0.0; sc.angle = 0.5;
    if (hfvis_ssao_scene_render(&cam_ok, &sc, cam_depth, cam_normals) != HFVIS_OK) exit(2);
    if (hfvis_view_perspective(&view_ok, eye, target, up, 0.9, 8, 8, 0.5, 10.0) != HFVIS_OK) exit(2);
    if (hfvis_voxelize_conservative(&m_box, &vg_ok, NULL, occ_box, NULL) != HFVIS_OK) exit(2);
    ro.pattern = HFVIS_LK_PATTERN_RANDOM;
    if (hfvis_lk_rays_build(32, 0.5, &ro, &lk_rays) != HFVIS_OK) exit(2);
    memset(&vf_ok, 0, sizeof vf_ok);
    if (hfvis_visfield_bounding_sphere(&m_box, vf_ok.center, &vf_ok.radius) != HFVIS_OK) exit(2);
    vf_ok.positions_n = 1; vf_ok.dir_res = 2; vf_ok.maps = vf_maps; vf_ok.maps_size = sizeof vf_maps;
    if (hfvis_visfield_build(&m_box, NULL, &vf_ok) != HFVIS_OK) exit(2);
    memset(&vf_obj, 0, sizeof vf_obj);
    vf_obj.field = &vf_ok; vf_obj.mesh = &m_box; vf_obj.bvh = &m_bvh;
    vf_obj.object_to_world[0] = vf_obj.object_to_world[5] = vf_obj.object_to_world[10] = 1.0;
    vf_obj.object_to_world[15] = 1.0;
    memset(&geo_ok, 0, sizeof geo_ok);
    geo_ok.grid.cell[0] = geo_ok.grid.cell[1] = geo_ok.grid.cell[2] = 1.0;
    geo_ok.grid.dims[0] = geo_ok.grid.dims[1] = geo_ok.grid.dims[2] = 3;
    for (i = 0; i < 27; i++) {
        vg_occ[i] = (i < 9) ? 1.0f : 0.0f;
        vg_nrm[3 * i] = 0.0f; vg_nrm[3 * i + 1] = 0.0f; vg_nrm[3 * i + 2] = (i < 9) ? 1.0f : 0.0f;
        vg_rad[3 * i] = vg_rad[3 * i + 1] = vg_rad[3 * i + 2] = (i < 9) ? 1.0f : 0.0f;
    }
    geo_ok.occupancy = vg_occ; geo_ok.normal = vg_nrm;
    if (hfvis_volgi_inject(&geo_ok, vg_rad, sh_prop) != HFVIS_OK) exit(2);
    memset(sh_accum, 0, sizeof sh_accum);
    make_lattice();
    make_depth_image();
    bad_bvh = m_bvh; bad_bvh.triangle_count = 3;
    if (hfvis_lk_lut_build(&lk_rays, 4, NULL, &lut_ok) != HFVIS_OK) exit(2);
}

static void teardown(void)
{
    hfvis_bvh_free(NULL, &m_bvh);
    hfvis_mesh_free(NULL, &m_box);
    hfvis_lk_lut_free(NULL, &lut_ok);
    hfvis_lk_rays_free(NULL, &lk_rays);
}

/* The standard invalid grids: g is replaced by each in turn inside expr (which must use &bg). */
#define GRID_CASES(expr) do { hfvis_grid bg; \
    bg = g_ok; bg.z = NULL; BAD('N', INV, expr); \
    bg = g_ok; bg.width = 0; BAD('Z', INV, expr); \
    bg = g_ok; bg.height = -1; BAD('G', INV, expr); \
    bg = g_ok; bg.stride = GW - 1; BAD('R', INV, expr); \
    bg = g_ok; bg.cell_size = 0.0; BAD('Z', INV, expr); \
    bg = g_ok; bg.cell_size = (double)NAN; BAD('F', INV, expr); \
    bg = g_ok; bg.cell_size = (double)INFINITY; BAD('F', INV, expr); \
    bg = g_ok; bg.stride = PTRDIFF_MAX; BAD('O', INV, expr); \
    } while (0)

/* The standard invalid sweep options, substituted as &bo. */
#define SWEEP_OPT_CASES(expr) do { hfvis_sweep_options bo; \
    bo = hfvis_sweep_options_default(); bo.border = (hfvis_border)99; BAD('E', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.border = (hfvis_border)-1; BAD('E', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.border_cells = -1; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.azimuth0_rad = (double)NAN; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.direction_begin = -1; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.direction_end = -2; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.direction_order = (hfvis_direction_order)3; BAD('E', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.rays = (hfvis_ray_mode)2; BAD('E', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.ray_denominator = -1; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.ray_denominator = HFVIS_RAY_DENOMINATOR_MAX + 1; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.ray_near_cells = -1; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.ray_near_cells = HFVIS_RAY_NEAR_CELLS_MAX + 1; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.max_distance = -1.0; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.max_distance = (double)NAN; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.origin_x = -1; bo.extent_width = bo.extent_height = 99; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.origin_y = 1; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.extent_width = 5; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.receiver_width = -1; bo.receiver_height = 1; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.receiver_height = 1; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.part_count = -1; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.part_index = 1; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.part_index = 2; bo.part_count = 2; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.part_index = -1; bo.part_count = 2; BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.part_count = 65537; BAD('S', INV, expr); \
    } while (0)

/* The P2 hull-tree routines honour a search radius but refuse a window (a proper one: finite
 * radius, open border) and a receiver rectangle, both valid elsewhere; substituted as &bo. */
#define P2_RADIUS_CASES(expr) do { hfvis_sweep_options bo; \
    bo = hfvis_sweep_options_default(); bo.max_distance = 2.5; OK(expr); \
    bo = hfvis_sweep_options_default(); bo.max_distance = (double)INFINITY; OK(expr); \
    bo = hfvis_sweep_options_default(); bo.max_distance = 2.5; bo.receiver_width = bo.receiver_height = 1; \
    BAD('S', INV, expr); \
    bo = hfvis_sweep_options_default(); bo.max_distance = 2.5; bo.origin_x = 1; \
    bo.extent_width = GW + 1; bo.extent_height = GH; BAD('S', INV, expr); \
    } while (0)

/* ========================================================================================== */
/* hfvis.c: status, codecs, fields, sampling, lattice, horizons, light                        */
/* ========================================================================================== */

static const char pgm_ok[] = "P2\n2 1\n255\n0 255\n";
static const char pgm_huge[] = "P5\n2000000 1\n255\n";

static void args_status_string(void)
{
    const char *s;
    begin("status_string");
    BADV('E', (s = hfvis_status_string((hfvis_status)999)) != NULL && strncmp(s, "HFVIS_ERR_UNKNOWN", 17) == 0);
    BADV('E', (s = hfvis_status_string((hfvis_status)-1)) != NULL && strncmp(s, "HFVIS_ERR_UNKNOWN", 17) == 0);
}

static void args_free(void)
{
    test_counting c;
    hfvis_allocator a = test_counting_allocator(&c, 0);
    begin("free");
    hfvis_free(NULL, NULL);
    hfvis_free(&a, NULL);
    BADV('N', c.allocs == 0 && c.live == 0);
}

static void args_crc32(void)
{
    begin("crc32");
    BADV('N', hfvis_crc32(0, NULL, 0) == 0u && hfvis_crc32(0x12345678u, NULL, 0) == 0x12345678u);
}

static void args_image_info_read(void)
{
    hfvis_image_info *info;
    begin("image_info_read");
    info = AT(hfvis_image_info);
    OK(hfvis_image_info_read(pgm_ok, sizeof pgm_ok - 1, info));
    BAD('N', INV, hfvis_image_info_read(NULL, 10, info));
    BAD('N', INV, hfvis_image_info_read(pgm_ok, sizeof pgm_ok - 1, NULL));
    BAD('Z', FMT, hfvis_image_info_read(pgm_ok, 0, info));
    BAD('O', LIM, hfvis_image_info_read(pgm_huge, sizeof pgm_huge - 1, info));
}

static void args_image_decode(void)
{
    hfvis_image_info *info;
    float *out;
    begin("image_decode");
    info = AT(hfvis_image_info);
    out = AF(2);
    OK(hfvis_image_decode(pgm_ok, sizeof pgm_ok - 1, out, 2, info));
    OK(hfvis_image_decode(pgm_ok, sizeof pgm_ok - 1, out, 2, NULL));
    BAD('N', INV, hfvis_image_decode(NULL, 10, out, 2, info));
    BAD('N', INV, hfvis_image_decode(pgm_ok, sizeof pgm_ok - 1, NULL, 2, info));
    BAD('Z', FMT, hfvis_image_decode(pgm_ok, 0, out, 2, info));
    BAD('Z', SMALL, hfvis_image_decode(pgm_ok, sizeof pgm_ok - 1, out, 0, info));
    BAD('R', SMALL, hfvis_image_decode(pgm_ok, sizeof pgm_ok - 1, out, 1, info));
    BAD('O', LIM, hfvis_image_decode(pgm_huge, sizeof pgm_huge - 1, out, 2, info));
}

static void args_pfm_encode_size(void)
{
    begin("pfm_encode_size");
    CHECK(hfvis_pfm_encode_size(2, 1, 1) > 0);
    BADV('Z', hfvis_pfm_encode_size(0, 1, 1) == 0);
    BADV('G', hfvis_pfm_encode_size(2, -1, 1) == 0);
    BADV('R', hfvis_pfm_encode_size(2, 1, 2) == 0);
    BADV('O', hfvis_pfm_encode_size(INT_MAX, INT_MAX, 3) == 0 || sizeof(size_t) > 8);
}

static void args_pgm_encode_size(void)
{
    begin("pgm_encode_size");
    CHECK(hfvis_pgm_encode_size(2, 1, 255) > 0);
    BADV('Z', hfvis_pgm_encode_size(0, 1, 255) == 0);
    BADV('G', hfvis_pgm_encode_size(2, -1, 255) == 0);
    BADV('R', hfvis_pgm_encode_size(2, 1, 0) == 0);
    BADV('R', hfvis_pgm_encode_size(2, 1, 65536) == 0);
}

static void args_pfm_encode(void)
{
    static const float px[2] = {1.0f, 2.0f};
    size_t need = hfvis_pfm_encode_size(2, 1, 1), *wr;
    unsigned char *out;
    begin("pfm_encode");
    out = ATN(unsigned char, need);
    wr = AT(size_t);
    OK(hfvis_pfm_encode(px, 2, 1, 1, 2, out, need, wr));
    BAD('N', INV, hfvis_pfm_encode(NULL, 2, 1, 1, 2, out, need, wr));
    BAD('N', INV, hfvis_pfm_encode(px, 2, 1, 1, 2, NULL, need, wr));
    BAD('N', INV, hfvis_pfm_encode(px, 2, 1, 1, 2, out, need, NULL));
    BAD('Z', INV, hfvis_pfm_encode(px, 0, 1, 1, 2, out, need, wr));
    BAD('G', INV, hfvis_pfm_encode(px, 2, -1, 1, 2, out, need, wr));
    BAD('R', INV, hfvis_pfm_encode(px, 2, 1, 2, 2, out, need, wr));
    BAD('R', INV, hfvis_pfm_encode(px, 2, 1, 1, 1, out, need, wr));
    BAD('R', SMALL, hfvis_pfm_encode(px, 2, 1, 1, 2, out, need - 1, wr));
    BAD('Z', SMALL, hfvis_pfm_encode(px, 2, 1, 1, 2, out, 0, wr));
    BAD('O', INV, hfvis_pfm_encode(px, INT_MAX, INT_MAX, 3, INT_MAX, out, need, wr));
}

static void args_pgm_encode(void)
{
    static const float px[2] = {1.0f, 2.0f};
    size_t need = hfvis_pgm_encode_size(2, 1, 255), *wr;
    unsigned char *out;
    begin("pgm_encode");
    out = ATN(unsigned char, need);
    wr = AT(size_t);
    OK(hfvis_pgm_encode(px, 2, 1, 2, 0.0f, 2.0f, 255, out, need, wr));
    BAD('N', INV, hfvis_pgm_encode(NULL, 2, 1, 2, 0.0f, 2.0f, 255, out, need, wr));
    BAD('N', INV, hfvis_pgm_encode(px, 2, 1, 2, 0.0f, 2.0f, 255, NULL, need, wr));
    BAD('N', INV, hfvis_pgm_encode(px, 2, 1, 2, 0.0f, 2.0f, 255, out, need, NULL));
    BAD('Z', INV, hfvis_pgm_encode(px, 0, 1, 2, 0.0f, 2.0f, 255, out, need, wr));
    BAD('G', INV, hfvis_pgm_encode(px, 2, -1, 2, 0.0f, 2.0f, 255, out, need, wr));
    BAD('R', INV, hfvis_pgm_encode(px, 2, 1, 1, 0.0f, 2.0f, 255, out, need, wr));
    BAD('F', INV, hfvis_pgm_encode(px, 2, 1, 2, (double)NAN, 2.0f, 255, out, need, wr));
    BAD('F', INV, hfvis_pgm_encode(px, 2, 1, 2, 0.0f, (double)INFINITY, 255, out, need, wr));
    BAD('R', INV, hfvis_pgm_encode(px, 2, 1, 2, 2.0f, 2.0f, 255, out, need, wr));
    BAD('Z', INV, hfvis_pgm_encode(px, 2, 1, 2, 0.0f, 2.0f, 0, out, need, wr));
    BAD('O', INV, hfvis_pgm_encode(px, 2, 1, 2, 0.0f, 2.0f, 65536, out, need, wr));
    BAD('R', SMALL, hfvis_pgm_encode(px, 2, 1, 2, 0.0f, 2.0f, 255, out, need - 1, wr));
}

static void args_image_load(void)
{
    float **px;
    hfvis_image_info *info;
    FILE *f = fopen(tmp_path("a.pgm"), "wb");
    if (f) { fputs(pgm_ok, f); fclose(f); }
    begin("image_load");
    px = AT(float *);
    info = AT(hfvis_image_info);
    arena_fill();
    base_status(hfvis_image_load(tmp_path("a.pgm"), NULL, px, info), __LINE__);
    hfvis_free(NULL, *px);
    BAD('N', INV, hfvis_image_load(NULL, NULL, px, info));
    BAD('N', INV, hfvis_image_load(tmp_path("a.pgm"), NULL, NULL, info));
    BAD('N', INV, hfvis_image_load(tmp_path("a.pgm"), NULL, px, NULL));
    BAD('R', IOE, hfvis_image_load(tmp_path("missing.pgm"), NULL, px, info));
}

/* Records the temporary names hfvis_write_file announces (on_temp). */
static char wf_seen[4096];
static int wf_calls, wf_nulls;
static void wf_on_temp(void *user, const char *tmp)
{
    (void)user;
    wf_calls++;
    if (!tmp) wf_nulls++;
    else if (strlen(tmp) < sizeof wf_seen) strcpy(wf_seen, tmp);
}

static void args_write_file(void)
{
    hfvis_write_options wo;
    char name[300], *leaf;
    const char *full;
    size_t k;
    begin("write_file");
    wo.on_temp = wf_on_temp;
    wo.user = NULL;
    wf_calls = wf_nulls = 0;
    OK(hfvis_write_file(tmp_path("w.bin"), "abc", 3, &wo));
    /* the name was announced before the file existed and withdrawn after the rename */
    CHECK(wf_calls == 2 && wf_nulls == 1 && strncmp(wf_seen, tmp_path("w.bin"), strlen(tmp_path("w.bin"))) == 0);
    CHECK(access(wf_seen, F_OK) != 0);
    OK(hfvis_write_file(tmp_path("empty.bin"), NULL, 0, NULL));
    /* a 250-byte leaf (legal: NAME_MAX 255) once failed, ENAMETOOLONG on "<leaf>.tmpXXXXXXXX" */
    for (k = 0; k < 250; k++) name[k] = (char)('a' + (int)(k % 26));
    name[250] = '\0';
    full = tmp_path(name);
    OK(hfvis_write_file(full, "abc", 3, &wo));
    BADV('R', access(full, F_OK) == 0);
    leaf = strrchr(wf_seen, '/');
    CHECK(leaf && strlen(leaf + 1) == 255); /* the cut leaf and its 12-byte suffix */
    CHECK(remove(full) == 0);
    BAD('N', INV, hfvis_write_file(NULL, "abc", 3, NULL));
    BAD('N', INV, hfvis_write_file(tmp_path("t.bin"), NULL, 3, NULL));
    BAD('Z', INV, hfvis_write_file("", "abc", 3, NULL));
    BAD('R', IOE, hfvis_write_file(bad_dir_path("t.bin"), "abc", 3, NULL));
    BADV('R', access(tmp_path("t.bin"), F_OK) != 0);
}

/* The streaming form: a committed file replaces path, a discarded one leaves it untouched, and
 * the temporary name is announced and withdrawn as by hfvis_write_file. */
static void args_write_begin(void)
{
    FILE *f = (FILE *)&f;
    char *tmp = (char *)&tmp;
    hfvis_write_options wo;
    begin("write_begin");
    wo.on_temp = wf_on_temp;
    wo.user = NULL;
    wf_calls = wf_nulls = 0;
    OK(hfvis_write_begin(tmp_path("b.bin"), &wo, &f, &tmp));
    CHECK(f != NULL && tmp != NULL && wf_calls == 1 && wf_nulls == 0 && strcmp(wf_seen, tmp) == 0);
    CHECK(fputs("abc", f) >= 0 && fseek(f, 0, SEEK_SET) == 0 && fputc('x', f) == 'x');
    OK(hfvis_write_end(tmp_path("b.bin"), f, tmp, 1, &wo));
    CHECK(wf_calls == 2 && wf_nulls == 1 && access(wf_seen, F_OK) != 0);
    {
        char got[8] = {0};
        FILE *r = fopen(tmp_path("b.bin"), "rb");
        CHECK(r != NULL);
        if (r) { CHECK(fread(got, 1, sizeof got, r) == 3 && memcmp(got, "xbc", 3) == 0); fclose(r); }
    }
    /* commit 0: the file is removed and path keeps its old content */
    OK(hfvis_write_begin(tmp_path("b.bin"), NULL, &f, &tmp));
    CHECK(fputs("new content", f) >= 0);
    OK(hfvis_write_end(tmp_path("b.bin"), f, tmp, 0, NULL));
    {
        char got[8] = {0};
        FILE *r = fopen(tmp_path("b.bin"), "rb");
        CHECK(r != NULL);
        if (r) { CHECK(fread(got, 1, sizeof got, r) == 3 && memcmp(got, "xbc", 3) == 0); fclose(r); }
    }
    f = (FILE *)&f;
    tmp = (char *)&tmp;
    BAD('N', INV, hfvis_write_begin(NULL, NULL, &f, &tmp));
    CHECK(f == NULL && tmp == NULL);
    BAD('N', INV, hfvis_write_begin(tmp_path("t.bin"), NULL, NULL, &tmp));
    BAD('N', INV, hfvis_write_begin(tmp_path("t.bin"), NULL, &f, NULL));
    BAD('Z', INV, hfvis_write_begin("", NULL, &f, &tmp));
    BAD('R', IOE, hfvis_write_begin(bad_dir_path("t.bin"), NULL, &f, &tmp));
    CHECK(f == NULL && tmp == NULL);
    BADV('R', access(tmp_path("t.bin"), F_OK) != 0);
}

static void args_write_end(void)
{
    FILE *f;
    char *tmp;
    begin("write_end");
    OK(hfvis_write_begin(tmp_path("e.bin"), NULL, &f, &tmp));
    OK(hfvis_write_end(tmp_path("e.bin"), f, tmp, 1, NULL));
    BAD('N', INV, hfvis_write_end(tmp_path("e.bin"), NULL, NULL, 1, NULL));
    /* a NULL path still closes the file and removes the temporary one */
    OK(hfvis_write_begin(tmp_path("e2.bin"), NULL, &f, &tmp));
    BAD('N', INV, hfvis_write_end(NULL, f, tmp, 1, NULL));
    BADV('N', access(tmp_path("e2.bin"), F_OK) != 0);
    /* the target became a directory between begin and end: the rename fails, nothing is left */
    OK(hfvis_write_begin(tmp_path("e3"), NULL, &f, &tmp));
    CHECK(mkdir(tmp_path("e3"), 0700) == 0);
    CHECK(fputs("abc", f) >= 0);
    BAD('R', IOE, hfvis_write_end(tmp_path("e3"), f, tmp, 1, NULL));
    CHECK(rmdir(tmp_path("e3")) == 0);
}

static void args_pfm_save(void)
{
    static const float px[2] = {1.0f, 2.0f};
    begin("pfm_save");
    OK(hfvis_pfm_save(tmp_path("s.pfm"), px, 2, 1, 1, 2));
    BAD('N', INV, hfvis_pfm_save(NULL, px, 2, 1, 1, 2));
    BAD('N', INV, hfvis_pfm_save(tmp_path("t.pfm"), NULL, 2, 1, 1, 2));
    BAD('Z', INV, hfvis_pfm_save(tmp_path("t.pfm"), px, 0, 1, 1, 2));
    BAD('G', INV, hfvis_pfm_save(tmp_path("t.pfm"), px, 2, -1, 1, 2));
    BAD('R', INV, hfvis_pfm_save(tmp_path("t.pfm"), px, 2, 1, 2, 2));
    BAD('R', IOE, hfvis_pfm_save(bad_dir_path("t.pfm"), px, 2, 1, 1, 2));
    BADV('R', access(tmp_path("t.pfm"), F_OK) != 0);
}

static void args_pgm_save(void)
{
    static const float px[2] = {1.0f, 2.0f};
    begin("pgm_save");
    OK(hfvis_pgm_save(tmp_path("s.pgm"), px, 2, 1, 2, 0.0f, 2.0f, 255));
    BAD('N', INV, hfvis_pgm_save(NULL, px, 2, 1, 2, 0.0f, 2.0f, 255));
    BAD('N', INV, hfvis_pgm_save(tmp_path("t.pgm"), NULL, 2, 1, 2, 0.0f, 2.0f, 255));
    BAD('Z', INV, hfvis_pgm_save(tmp_path("t.pgm"), px, 0, 1, 2, 0.0f, 2.0f, 255));
    BAD('G', INV, hfvis_pgm_save(tmp_path("t.pgm"), px, 2, -1, 2, 0.0f, 2.0f, 255));
    BAD('F', INV, hfvis_pgm_save(tmp_path("t.pgm"), px, 2, 1, 2, (double)NAN, 2.0f, 255));
    BAD('R', INV, hfvis_pgm_save(tmp_path("t.pgm"), px, 2, 1, 2, 0.0f, 2.0f, 70000));
    BAD('R', IOE, hfvis_pgm_save(bad_dir_path("t.pgm"), px, 2, 1, 2, 0.0f, 2.0f, 255));
    BADV('R', access(tmp_path("t.pgm"), F_OK) != 0);
}

static const char pgm_range_ok[] = "P2\n# hfvis range 0 2 nodata 0\n2 1 65535\n0 65535\n";

static void args_pgm_range_encode_size(void)
{
    begin("pgm_range_encode_size");
    CHECK(hfvis_pgm_range_encode_size(2, 1, 0.0f, 2.0f) > 0);
    BADV('Z', hfvis_pgm_range_encode_size(0, 1, 0.0f, 2.0f) == 0);
    BADV('G', hfvis_pgm_range_encode_size(2, -1, 0.0f, 2.0f) == 0);
    BADV('F', hfvis_pgm_range_encode_size(2, 1, (float)NAN, 2.0f) == 0);
    BADV('F', hfvis_pgm_range_encode_size(2, 1, 0.0f, (float)INFINITY) == 0);
    BADV('R', hfvis_pgm_range_encode_size(2, 1, 2.0f, 2.0f) == 0);
}

static void args_pgm_range_encode(void)
{
    static const float px[2] = {1.0f, 2.0f};
    size_t need = hfvis_pgm_range_encode_size(2, 1, 0.0f, 2.0f), *wr;
    unsigned char *out;
    begin("pgm_range_encode");
    out = ATN(unsigned char, need);
    wr = AT(size_t);
    OK(hfvis_pgm_range_encode(px, 2, 1, 2, 0.0f, 2.0f, out, need, wr));
    BAD('N', INV, hfvis_pgm_range_encode(NULL, 2, 1, 2, 0.0f, 2.0f, out, need, wr));
    BAD('N', INV, hfvis_pgm_range_encode(px, 2, 1, 2, 0.0f, 2.0f, NULL, need, wr));
    BAD('N', INV, hfvis_pgm_range_encode(px, 2, 1, 2, 0.0f, 2.0f, out, need, NULL));
    BAD('Z', INV, hfvis_pgm_range_encode(px, 0, 1, 2, 0.0f, 2.0f, out, need, wr));
    BAD('G', INV, hfvis_pgm_range_encode(px, 2, -1, 2, 0.0f, 2.0f, out, need, wr));
    BAD('R', INV, hfvis_pgm_range_encode(px, 2, 1, 1, 0.0f, 2.0f, out, need, wr));
    BAD('F', INV, hfvis_pgm_range_encode(px, 2, 1, 2, (float)NAN, 2.0f, out, need, wr));
    BAD('R', INV, hfvis_pgm_range_encode(px, 2, 1, 2, 2.0f, 2.0f, out, need, wr));
    BAD('R', SMALL, hfvis_pgm_range_encode(px, 2, 1, 2, 0.0f, 2.0f, out, need - 1, wr));
    BAD('Z', SMALL, hfvis_pgm_range_encode(px, 2, 1, 2, 0.0f, 2.0f, out, 0, wr));
}

static void args_pgm_range_save(void)
{
    static const float px[2] = {1.0f, 2.0f};
    begin("pgm_range_save");
    OK(hfvis_pgm_range_save(tmp_path("r.pgm"), px, 2, 1, 2, 0.0f, 2.0f));
    BAD('N', INV, hfvis_pgm_range_save(NULL, px, 2, 1, 2, 0.0f, 2.0f));
    BAD('N', INV, hfvis_pgm_range_save(tmp_path("u.pgm"), NULL, 2, 1, 2, 0.0f, 2.0f));
    BAD('Z', INV, hfvis_pgm_range_save(tmp_path("u.pgm"), px, 0, 1, 2, 0.0f, 2.0f));
    BAD('G', INV, hfvis_pgm_range_save(tmp_path("u.pgm"), px, 2, -1, 2, 0.0f, 2.0f));
    BAD('F', INV, hfvis_pgm_range_save(tmp_path("u.pgm"), px, 2, 1, 2, (float)NAN, 2.0f));
    BAD('R', INV, hfvis_pgm_range_save(tmp_path("u.pgm"), px, 2, 1, 1, 0.0f, 2.0f));
    BAD('R', IOE, hfvis_pgm_range_save(bad_dir_path("u.pgm"), px, 2, 1, 2, 0.0f, 2.0f));
    BADV('R', access(tmp_path("u.pgm"), F_OK) != 0);
}

static void args_pgm_range_read(void)
{
    float *lo, *hi;
    begin("pgm_range_read");
    lo = AT(float);
    hi = AT(float);
    OK(hfvis_pgm_range_read(pgm_range_ok, sizeof pgm_range_ok - 1, lo, hi));
    BAD('N', INV, hfvis_pgm_range_read(NULL, 10, lo, hi));
    BAD('N', INV, hfvis_pgm_range_read(pgm_range_ok, sizeof pgm_range_ok - 1, NULL, hi));
    BAD('N', INV, hfvis_pgm_range_read(pgm_range_ok, sizeof pgm_range_ok - 1, lo, NULL));
    BAD('Z', FMT, hfvis_pgm_range_read(pgm_range_ok, 0, lo, hi));
    BAD('R', FMT, hfvis_pgm_range_read(pgm_ok, sizeof pgm_ok - 1, lo, hi)); /* no range comment */
    BAD('O', LIM, hfvis_pgm_range_read(pgm_huge, sizeof pgm_huge - 1, lo, hi));
}

static void args_pgm_range_decode(void)
{
    hfvis_image_info *info;
    float *out;
    begin("pgm_range_decode");
    info = AT(hfvis_image_info);
    out = AF(2);
    OK(hfvis_pgm_range_decode(pgm_range_ok, sizeof pgm_range_ok - 1, out, 2, info));
    OK(hfvis_pgm_range_decode(pgm_range_ok, sizeof pgm_range_ok - 1, out, 2, NULL));
    BAD('N', INV, hfvis_pgm_range_decode(NULL, 10, out, 2, info));
    BAD('N', INV, hfvis_pgm_range_decode(pgm_range_ok, sizeof pgm_range_ok - 1, NULL, 2, info));
    BAD('Z', FMT, hfvis_pgm_range_decode(pgm_range_ok, 0, out, 2, info));
    BAD('Z', SMALL, hfvis_pgm_range_decode(pgm_range_ok, sizeof pgm_range_ok - 1, out, 0, info));
    BAD('R', SMALL, hfvis_pgm_range_decode(pgm_range_ok, sizeof pgm_range_ok - 1, out, 1, info));
    BAD('R', FMT, hfvis_pgm_range_decode(pgm_ok, sizeof pgm_ok - 1, out, 2, info));
    BAD('O', LIM, hfvis_pgm_range_decode(pgm_huge, sizeof pgm_huge - 1, out, 2, info));
}

static hfvis_field field_ok(void)
{
    hfvis_field f;
    memset(&f, 0, sizeof f);
    f.kind = HFVIS_FIELD_SINUSOID; f.amplitude = 1.0; f.wavelength = 4.0;
    return f;
}

static void args_field_height(void)
{
    hfvis_field f = field_ok(), b;
    begin("field_height");
    CHECK(isfinite(hfvis_field_height(&f, 1.0, 2.0)));
    BADV('N', isnan(hfvis_field_height(NULL, 1.0, 2.0)));
    b = f; b.kind = (hfvis_field_kind)999;
    BADV('E', isnan(hfvis_field_height(&b, 1.0, 2.0)));
    b = f; b.wavelength = (double)NAN;
    BADV('S', isnan(hfvis_field_height(&b, 1.0, 2.0)));
    BADV('F', isnan(hfvis_field_height(&f, (double)NAN, 2.0)));
}

static void args_field_generate(void)
{
    hfvis_field f = field_ok(), b;
    float *out;
    begin("field_generate");
    out = AF(GW * GH);
    OK(hfvis_field_generate(&f, GW, GH, GW, out));
    BAD('N', INV, hfvis_field_generate(NULL, GW, GH, GW, out));
    BAD('N', INV, hfvis_field_generate(&f, GW, GH, GW, NULL));
    BAD('Z', INV, hfvis_field_generate(&f, 0, GH, GW, out));
    BAD('G', INV, hfvis_field_generate(&f, GW, -1, GW, out));
    BAD('R', INV, hfvis_field_generate(&f, GW, GH, GW - 1, out));
    BAD('O', INV, hfvis_field_generate(&f, GW, 3, PTRDIFF_MAX, out));
    b = f; b.kind = (hfvis_field_kind)999; BAD('E', INV, hfvis_field_generate(&b, GW, GH, GW, out));
    b = f; b.kind = (hfvis_field_kind)0; BAD('E', INV, hfvis_field_generate(&b, GW, GH, GW, out));
    b = f; b.wavelength = (double)NAN; BAD('F', INV, hfvis_field_generate(&b, GW, GH, GW, out));
    b = f; b.amplitude = (double)INFINITY; BAD('F', INV, hfvis_field_generate(&b, GW, GH, GW, out));
    b = f; b.wavelength = 0.0; BAD('S', INV, hfvis_field_generate(&b, GW, GH, GW, out));
}

static void args_grid_sample(void)
{
    hfvis_grid b = g_ok;
    begin("grid_sample");
    CHECK(isfinite(hfvis_grid_sample(&g_ok, 1.5, 1.5)));
    BADV('N', isnan(hfvis_grid_sample(NULL, 1.0, 1.0)));
    BADV('F', isnan(hfvis_grid_sample(&g_ok, (double)NAN, 1.0)));
    b.width = 0;
    BADV('Z', isnan(hfvis_grid_sample(&b, 1.0, 1.0)));
}

static void args_normals_compute(void)
{
    float *out;
    begin("normals_compute");
    out = AF(3 * GW * GH);
    OK(hfvis_normals_compute(&g_ok, out));
    BAD('N', INV, hfvis_normals_compute(NULL, out));
    BAD('N', INV, hfvis_normals_compute(&g_ok, NULL));
    GRID_CASES(hfvis_normals_compute(&bg, out));
}

static void args_exact_grid_compute(void)
{
    double *out;
    begin("exact_grid_compute");
    out = AD(GW * GH + 1);
    OK(hfvis_exact_grid_compute(&g_ok, out));
    BAD('N', INV, hfvis_exact_grid_compute(NULL, out));
    BAD('N', INV, hfvis_exact_grid_compute(&g_ok, NULL));
    GRID_CASES(hfvis_exact_grid_compute(&bg, out));
}

static void args_exact_grid_rows(void)
{
    double *out;
    int cls;
    begin("exact_grid_rows");
    out = AD(GW * GH + 1);
    OK(hfvis_exact_grid_rows(&g_ok, 0, GH, out, &cls));
    BAD('N', INV, hfvis_exact_grid_rows(NULL, 0, GH, out, &cls));
    OK(hfvis_exact_grid_rows(&g_ok, 0, GH, NULL, &cls)); /* the class alone */
    BAD('N', INV, hfvis_exact_grid_rows(&g_ok, 0, GH, out, NULL));
    BAD('R', INV, hfvis_exact_grid_rows(&g_ok, -1, GH, out, &cls));
    BAD('R', INV, hfvis_exact_grid_rows(&g_ok, 0, GH + 1, out, &cls));
    BAD('R', INV, hfvis_exact_grid_rows(&g_ok, 3, 3, out, &cls));
    BAD('R', INV, hfvis_exact_grid_rows(&g_ok, 4, 3, out, &cls));
    BAD('R', INV, hfvis_exact_grid_rows(&g_ok, INT_MAX, INT_MIN, out, &cls));
    GRID_CASES(hfvis_exact_grid_rows(&bg, 0, 1, out, &cls));
}

static void args_lattice_init(void)
{
    hfvis_lattice *L;
    begin("lattice_init");
    L = AT(hfvis_lattice);
    OK(hfvis_lattice_init(L, GW, GH, 0.3));
    BAD('N', INV, hfvis_lattice_init(NULL, GW, GH, 0.3));
    BAD('Z', INV, hfvis_lattice_init(L, 0, GH, 0.3));
    BAD('G', INV, hfvis_lattice_init(L, GW, -1, 0.3));
    BAD('F', INV, hfvis_lattice_init(L, GW, GH, (double)NAN));
    BAD('F', INV, hfvis_lattice_init(L, GW, GH, (double)INFINITY));
    BAD('O', LIM, hfvis_lattice_init(L, INT_MAX, INT_MAX, 0.3));
}

static void args_lattice_nodes(void)
{
    hfvis_lattice L;
    begin("lattice_nodes");
    CHECK(hfvis_lattice_init(&L, GW, GH, 0.3) == HFVIS_OK && hfvis_lattice_nodes(&L) > 0);
    BADV('N', hfvis_lattice_nodes(NULL) == 0);
}

static void args_tile_halo(void)
{
    begin("tile_halo");
    CHECK(hfvis_tile_halo(10.0, 2.0, HFVIS_RAYS_LATTICE) == 5 + HFVIS_TILE_HALO_LATTICE);
    CHECK(hfvis_tile_halo(10.5, 2.0, HFVIS_RAYS_EXACT) == 6 + HFVIS_TILE_HALO_EXACT);
    BADV('Z', hfvis_tile_halo(0.0, 1.0, HFVIS_RAYS_LATTICE) == -1);
    BADV('Z', hfvis_tile_halo(1.0, 0.0, HFVIS_RAYS_LATTICE) == -1);
    BADV('G', hfvis_tile_halo(-1.0, 1.0, HFVIS_RAYS_LATTICE) == -1);
    BADV('F', hfvis_tile_halo((double)INFINITY, 1.0, HFVIS_RAYS_LATTICE) == -1);
    BADV('F', hfvis_tile_halo((double)NAN, 1.0, HFVIS_RAYS_EXACT) == -1);
    BADV('F', hfvis_tile_halo(1e300, 1e-300, HFVIS_RAYS_EXACT) == -1);
    BADV('E', hfvis_tile_halo(1.0, 1.0, (hfvis_ray_mode)7) == -1);
}

static void args_lattice_line(void)
{
    hfvis_lattice L;
    int *a, *b;
    begin("lattice_line");
    a = AT(int);
    b = AT(int);
    CHECK(hfvis_lattice_init(&L, GW, GH, 0.0) == HFVIS_OK && hfvis_lattice_line(&L, L.j_min, a, b) > 0);
    BADV('N', hfvis_lattice_line(NULL, 0, a, b) == 0);
    BADV('R', hfvis_lattice_line(&L, L.j_max + 1, a, b) == 0);
    BADV('R', hfvis_lattice_line(&L, INT_MIN, a, b) == 0);
}

static void args_sweep_options_default(void)
{
    hfvis_sweep_options o = hfvis_sweep_options_default();
    begin("sweep_options_default");
    CHECK(o.border == HFVIS_BORDER_DEFAULT || o.border == HFVIS_BORDER_OPEN);
}

static void args_line_horizons(void)
{
    static const double d[4] = {0, 1, 2, 3}, h[4] = {1, 0, 2, 0}, dbad[4] = {0, 1, 1, 3};
    static const double dnan[4] = {0, (double)NAN, 2, 3};
    double *t;
    int *c, *st;
    begin("line_horizons");
    t = AD(4); c = ATN(int, 4); st = ATN(int, 4);
    OK(hfvis_line_horizons(d, h, 4, t, c, st));
    OK(hfvis_line_horizons(d, h, 4, t, NULL, st));
    BAD('N', INV, hfvis_line_horizons(NULL, h, 4, t, c, st));
    BAD('N', INV, hfvis_line_horizons(d, NULL, 4, t, c, st));
    BAD('N', INV, hfvis_line_horizons(d, h, 4, NULL, c, st));
    BAD('N', INV, hfvis_line_horizons(d, h, 4, t, c, NULL));
    BAD('G', INV, hfvis_line_horizons(d, h, -1, t, c, st));
    BAD('R', INV, hfvis_line_horizons(dbad, h, 4, t, c, st));
    BAD('F', INV, hfvis_line_horizons(dnan, h, 4, t, c, st));
}

static void args_line_horizons_naive(void)
{
    static const double d[4] = {0, 1, 2, 3}, h[4] = {1, 0, 2, 0}, dbad[4] = {0, 1, 1, 3};
    static const double dnan[4] = {0, (double)NAN, 2, 3};
    double *t;
    int *c;
    begin("line_horizons_naive");
    t = AD(4); c = ATN(int, 4);
    OK(hfvis_line_horizons_naive(d, h, 4, t, c));
    BAD('N', INV, hfvis_line_horizons_naive(NULL, h, 4, t, c));
    BAD('N', INV, hfvis_line_horizons_naive(d, NULL, 4, t, c));
    BAD('N', INV, hfvis_line_horizons_naive(d, h, 4, NULL, c));
    BAD('G', INV, hfvis_line_horizons_naive(d, h, -1, t, c));
    BAD('R', INV, hfvis_line_horizons_naive(dbad, h, 4, t, c));
    BAD('F', INV, hfvis_line_horizons_naive(dnan, h, 4, t, c));
}

static void args_horizon_lattice(void)
{
    hfvis_lattice L;
    float *out;
    begin("horizon_lattice");
    hfvis_lattice_init(&L, GW, GH, 0.3);
    out = AF(hfvis_lattice_nodes(&L));
    OK(hfvis_horizon_lattice(&g_ok, 0.3, NULL, out));
    BAD('N', INV, hfvis_horizon_lattice(NULL, 0.3, NULL, out));
    BAD('N', INV, hfvis_horizon_lattice(&g_ok, 0.3, NULL, NULL));
    BAD('F', INV, hfvis_horizon_lattice(&g_ok, (double)NAN, NULL, out));
    BAD('F', INV, hfvis_horizon_lattice(&g_ok, -(double)INFINITY, NULL, out));
    GRID_CASES(hfvis_horizon_lattice(&bg, 0.3, NULL, out));
    SWEEP_OPT_CASES(hfvis_horizon_lattice(&g_ok, 0.3, &bo, out));
}

static void args_horizon_lattice_naive(void)
{
    hfvis_lattice L;
    float *out;
    begin("horizon_lattice_naive");
    hfvis_lattice_init(&L, GW, GH, 0.3);
    out = AF(hfvis_lattice_nodes(&L));
    OK(hfvis_horizon_lattice_naive(&g_ok, 0.3, NULL, out));
    BAD('N', INV, hfvis_horizon_lattice_naive(NULL, 0.3, NULL, out));
    BAD('N', INV, hfvis_horizon_lattice_naive(&g_ok, 0.3, NULL, NULL));
    BAD('F', INV, hfvis_horizon_lattice_naive(&g_ok, (double)NAN, NULL, out));
    GRID_CASES(hfvis_horizon_lattice_naive(&bg, 0.3, NULL, out));
    SWEEP_OPT_CASES(hfvis_horizon_lattice_naive(&g_ok, 0.3, &bo, out));
}

static void args_horizon_direction(void)
{
    float *out;
    begin("horizon_direction");
    out = AF(GW * GH);
    OK(hfvis_horizon_direction(&g_ok, 4, 1, NULL, out, GW));
    BAD('N', INV, hfvis_horizon_direction(NULL, 4, 1, NULL, out, GW));
    BAD('N', INV, hfvis_horizon_direction(&g_ok, 4, 1, NULL, NULL, GW));
    BAD('Z', INV, hfvis_horizon_direction(&g_ok, 0, 0, NULL, out, GW));
    BAD('G', INV, hfvis_horizon_direction(&g_ok, -4, 1, NULL, out, GW));
    BAD('G', INV, hfvis_horizon_direction(&g_ok, 4, -1, NULL, out, GW));
    BAD('R', INV, hfvis_horizon_direction(&g_ok, 4, 4, NULL, out, GW));
    BAD('R', INV, hfvis_horizon_direction(&g_ok, 4, 1, NULL, out, GW - 1));
    BAD('O', INV, hfvis_horizon_direction(&g_ok, 4, 1, NULL, out, PTRDIFF_MAX));
    GRID_CASES(hfvis_horizon_direction(&bg, 4, 1, NULL, out, GW));
    SWEEP_OPT_CASES(hfvis_horizon_direction(&g_ok, 4, 1, &bo, out, GW));
}

static void args_horizon_map(void)
{
    float *out;
    begin("horizon_map");
    out = AF(4 * GW * GH);
    OK(hfvis_horizon_map(&g_ok, 4, NULL, out));
    BAD('N', INV, hfvis_horizon_map(NULL, 4, NULL, out));
    BAD('N', INV, hfvis_horizon_map(&g_ok, 4, NULL, NULL));
    BAD('Z', INV, hfvis_horizon_map(&g_ok, 0, NULL, out));
    BAD('G', INV, hfvis_horizon_map(&g_ok, -1, NULL, out));
    GRID_CASES(hfvis_horizon_map(&bg, 4, NULL, out));
    SWEEP_OPT_CASES(hfvis_horizon_map(&g_ok, 4, &bo, out));
}

static void args_horizon_reference(void)
{
    static const float pts[4] = {1.0f, 1.0f, 2.0f, 1.0f};
    hfvis_march_options m;
    float *out;
    begin("horizon_reference");
    out = AF(2 * 4);
    memset(&m, 0, sizeof m);
    OK(hfvis_horizon_reference(&g_ok, 4, NULL, NULL, pts, 2, out));
    BAD('N', INV, hfvis_horizon_reference(NULL, 4, NULL, NULL, pts, 2, out));
    BAD('N', INV, hfvis_horizon_reference(&g_ok, 4, NULL, NULL, NULL, 2, out));
    BAD('N', INV, hfvis_horizon_reference(&g_ok, 4, NULL, NULL, pts, 2, NULL));
    BAD('Z', INV, hfvis_horizon_reference(&g_ok, 0, NULL, NULL, pts, 2, out));
    BAD('G', INV, hfvis_horizon_reference(&g_ok, -1, NULL, NULL, pts, 2, out));
    m.step_cells = -1.0; BAD('S', INV, hfvis_horizon_reference(&g_ok, 4, NULL, &m, pts, 2, out));
    m.step_cells = (double)NAN; BAD('F', INV, hfvis_horizon_reference(&g_ok, 4, NULL, &m, pts, 2, out));
    m.step_cells = 0.0; m.max_distance_cells = -1.0;
    BAD('S', INV, hfvis_horizon_reference(&g_ok, 4, NULL, &m, pts, 2, out));
    BAD('O', INV, hfvis_horizon_reference(&g_ok, INT_MAX, NULL, NULL, pts, SIZE_MAX / 2, out));
    GRID_CASES(hfvis_horizon_reference(&bg, 4, NULL, NULL, pts, 2, out));
    SWEEP_OPT_CASES(hfvis_horizon_reference(&g_ok, 4, &bo, NULL, pts, 2, out));
}

static double plane_fn(void *user, double x, double y)
{
    (void)user;
    return 0.1 * x + 0.05 * y;
}

static void args_horizon_reference_fn(void)
{
    static const float pts[4] = {1.0f, 1.0f, 2.0f, 1.0f};
    float *out;
    begin("horizon_reference_fn");
    out = AF(2 * 4);
    OK(hfvis_horizon_reference_fn(plane_fn, NULL, GW, GH, 1.0, 4, NULL, NULL, pts, 2, out));
    BAD('N', INV, hfvis_horizon_reference_fn(NULL, NULL, GW, GH, 1.0, 4, NULL, NULL, pts, 2, out));
    BAD('N', INV, hfvis_horizon_reference_fn(plane_fn, NULL, GW, GH, 1.0, 4, NULL, NULL, NULL, 2, out));
    BAD('N', INV, hfvis_horizon_reference_fn(plane_fn, NULL, GW, GH, 1.0, 4, NULL, NULL, pts, 2, NULL));
    BAD('Z', INV, hfvis_horizon_reference_fn(plane_fn, NULL, 0, GH, 1.0, 4, NULL, NULL, pts, 2, out));
    BAD('G', INV, hfvis_horizon_reference_fn(plane_fn, NULL, GW, -1, 1.0, 4, NULL, NULL, pts, 2, out));
    BAD('Z', INV, hfvis_horizon_reference_fn(plane_fn, NULL, GW, GH, 0.0, 4, NULL, NULL, pts, 2, out));
    BAD('F', INV, hfvis_horizon_reference_fn(plane_fn, NULL, GW, GH, (double)NAN, 4, NULL, NULL, pts, 2, out));
    BAD('Z', INV, hfvis_horizon_reference_fn(plane_fn, NULL, GW, GH, 1.0, 0, NULL, NULL, pts, 2, out));
    SWEEP_OPT_CASES(hfvis_horizon_reference_fn(plane_fn, NULL, GW, GH, 1.0, 4, &bo, NULL, pts, 2, out));
}

static void args_openness(void)
{
    hfvis_openness_options oo;
    float *out;
    begin("openness");
    out = AF(GW * GH);
    memset(&oo, 0, sizeof oo);
    OK(hfvis_openness(&g_ok, 4, NULL, NULL, out, GW));
    oo.radius = 2.0;
    oo.negative = 1;
    OK(hfvis_openness(&g_ok, 4, &oo, NULL, out, GW));
    oo.negative = 2; /* both: two planes */
    OK(hfvis_openness(&g_ok, 4, &oo, NULL, AF(2 * GW * GH), GW));
    oo.negative = 1;
    BAD('N', INV, hfvis_openness(NULL, 4, NULL, NULL, out, GW));
    BAD('N', INV, hfvis_openness(&g_ok, 4, NULL, NULL, NULL, GW));
    BAD('Z', INV, hfvis_openness(&g_ok, 0, NULL, NULL, out, GW));
    BAD('G', INV, hfvis_openness(&g_ok, -4, NULL, NULL, out, GW));
    BAD('R', INV, hfvis_openness(&g_ok, 4, NULL, NULL, out, GW - 1));
    BAD('O', INV, hfvis_openness(&g_ok, 4, NULL, NULL, out, PTRDIFF_MAX));
    oo.radius = -1.0; BAD('S', INV, hfvis_openness(&g_ok, 4, &oo, NULL, out, GW));
    oo.radius = (double)NAN; BAD('F', INV, hfvis_openness(&g_ok, 4, &oo, NULL, out, GW));
    oo.radius = (double)INFINITY; BAD('F', INV, hfvis_openness(&g_ok, 4, &oo, NULL, out, GW));
    oo.radius = 1.0; oo.step_cells = -1.0; BAD('S', INV, hfvis_openness(&g_ok, 4, &oo, NULL, out, GW));
    oo.step_cells = (double)NAN; BAD('F', INV, hfvis_openness(&g_ok, 4, &oo, NULL, out, GW));
    oo.step_cells = 0.0; oo.negative = 3; BAD('S', INV, hfvis_openness(&g_ok, 4, &oo, NULL, out, GW));
    oo.negative = -1; BAD('S', INV, hfvis_openness(&g_ok, 4, &oo, NULL, out, GW));
    GRID_CASES(hfvis_openness(&bg, 4, NULL, NULL, out, GW));
    SWEEP_OPT_CASES(hfvis_openness(&g_ok, 4, NULL, &bo, out, GW));
    { /* a receiver rectangle with a radius; not without one, nor a search radius or a window */
        hfvis_sweep_options ro = hfvis_sweep_options_default();
        ro.receiver_x = ro.receiver_y = 1;
        ro.receiver_width = ro.receiver_height = 2;
        oo.negative = 0;
        oo.radius = 2.0;
        OK(hfvis_openness(&g_ok, 4, &oo, &ro, out, GW));
        oo.radius = 0.0;
        BAD('S', INV, hfvis_openness(&g_ok, 4, &oo, &ro, out, GW));
        ro = hfvis_sweep_options_default();
        ro.max_distance = 2.0;
        oo.radius = 2.0;
        BAD('S', INV, hfvis_openness(&g_ok, 4, &oo, &ro, out, GW));
    }
}

static void args_sweep_azimuths(void)
{
    double *az, *w;
    hfvis_sweep_options eo = hfvis_sweep_options_default();
    begin("sweep_azimuths");
    az = AD(8);
    w = AD(8);
    eo.rays = HFVIS_RAYS_EXACT;
    OK(hfvis_sweep_azimuths(8, &eo, az, w));
    BAD('N', INV, hfvis_sweep_azimuths(8, &eo, NULL, NULL));
    BAD('Z', INV, hfvis_sweep_azimuths(0, &eo, az, w));
    BAD('G', INV, hfvis_sweep_azimuths(-3, &eo, az, w));
    SWEEP_OPT_CASES(hfvis_sweep_azimuths(8, &bo, az, w));
}

static void args_horizon_exact_naive(void)
{
    float *out;
    begin("horizon_exact_naive");
    out = AF(4 * GW * GH);
    OK(hfvis_horizon_exact_naive(&g_ok, 4, NULL, out));
    BAD('N', INV, hfvis_horizon_exact_naive(NULL, 4, NULL, out));
    BAD('N', INV, hfvis_horizon_exact_naive(&g_ok, 4, NULL, NULL));
    BAD('Z', INV, hfvis_horizon_exact_naive(&g_ok, 0, NULL, out));
    BAD('G', INV, hfvis_horizon_exact_naive(&g_ok, -1, NULL, out));
    GRID_CASES(hfvis_horizon_exact_naive(&bg, 4, NULL, out));
    SWEEP_OPT_CASES(hfvis_horizon_exact_naive(&g_ok, 4, &bo, out));
}

static void args_sector_weight(void)
{
    begin("sector_weight");
    CHECK(isfinite(hfvis_sector_weight(4, 1.0, 0.0, 1.0)));
    BADV('Z', isnan(hfvis_sector_weight(0, 1.0, 0.0, 1.0)));
    BADV('G', isnan(hfvis_sector_weight(-1, 1.0, 0.0, 1.0)));
    BADV('F', isnan(hfvis_sector_weight(4, (double)NAN, 0.0, 1.0)));
}

static void args_sky_light(void)
{
    float *out;
    begin("sky_light");
    out = AF(GW * GH);
    OK(hfvis_sky_light(&g_ok, 4, 1.0f, 1.0f, NULL, out, GW));
    BAD('N', INV, hfvis_sky_light(NULL, 4, 1.0f, 1.0f, NULL, out, GW));
    BAD('N', INV, hfvis_sky_light(&g_ok, 4, 1.0f, 1.0f, NULL, NULL, GW));
    BAD('Z', INV, hfvis_sky_light(&g_ok, 0, 1.0f, 1.0f, NULL, out, GW));
    BAD('G', INV, hfvis_sky_light(&g_ok, -2, 1.0f, 1.0f, NULL, out, GW));
    BAD('F', INV, hfvis_sky_light(&g_ok, 4, (double)NAN, 1.0f, NULL, out, GW));
    BAD('F', INV, hfvis_sky_light(&g_ok, 4, 1.0f, (double)INFINITY, NULL, out, GW));
    BAD('R', INV, hfvis_sky_light(&g_ok, 4, 1.0f, 1.0f, NULL, out, GW - 1));
    BAD('O', INV, hfvis_sky_light(&g_ok, 4, 1.0f, 1.0f, NULL, out, PTRDIFF_MAX));
    GRID_CASES(hfvis_sky_light(&bg, 4, 1.0f, 1.0f, NULL, out, GW));
    SWEEP_OPT_CASES(hfvis_sky_light(&g_ok, 4, 1.0f, 1.0f, &bo, out, GW));
}

static void args_sky_light_from_map(void)
{
    float *out;
    begin("sky_light_from_map");
    out = AF(GW * GH);
    OK(hfvis_sky_light_from_map(&g_ok, 4, 0.0, g_map, 1.0f, 1.0f, NULL, out, GW));
    BAD('N', INV, hfvis_sky_light_from_map(NULL, 4, 0.0, g_map, 1.0f, 1.0f, NULL, out, GW));
    BAD('N', INV, hfvis_sky_light_from_map(&g_ok, 4, 0.0, NULL, 1.0f, 1.0f, NULL, out, GW));
    BAD('N', INV, hfvis_sky_light_from_map(&g_ok, 4, 0.0, g_map, 1.0f, 1.0f, NULL, NULL, GW));
    BAD('Z', INV, hfvis_sky_light_from_map(&g_ok, 0, 0.0, g_map, 1.0f, 1.0f, NULL, out, GW));
    BAD('G', INV, hfvis_sky_light_from_map(&g_ok, -4, 0.0, g_map, 1.0f, 1.0f, NULL, out, GW));
    BAD('F', INV, hfvis_sky_light_from_map(&g_ok, 4, (double)NAN, g_map, 1.0f, 1.0f, NULL, out, GW));
    BAD('F', INV, hfvis_sky_light_from_map(&g_ok, 4, 0.0, g_map, (double)INFINITY, 1.0f, NULL, out, GW));
    BAD('F', INV, hfvis_sky_light_from_map(&g_ok, 4, 0.0, g_map, 1.0f, (double)NAN, NULL, out, GW));
    BAD('R', INV, hfvis_sky_light_from_map(&g_ok, 4, 0.0, g_map, 1.0f, 1.0f, NULL, out, GW - 1));
    BAD('O', INV, hfvis_sky_light_from_map(&g_ok, 4, 0.0, g_map, 1.0f, 1.0f, NULL, out, PTRDIFF_MAX));
    GRID_CASES(hfvis_sky_light_from_map(&bg, 4, 0.0, g_map, 1.0f, 1.0f, NULL, out, GW));
}

static void args_sky_view_factor(void)
{
    float *out;
    begin("sky_view_factor");
    out = AF(GW * GH);
    OK(hfvis_sky_view_factor(&g_ok, 4, NULL, out, GW));
    BAD('N', INV, hfvis_sky_view_factor(NULL, 4, NULL, out, GW));
    BAD('N', INV, hfvis_sky_view_factor(&g_ok, 4, NULL, NULL, GW));
    BAD('Z', INV, hfvis_sky_view_factor(&g_ok, 0, NULL, out, GW));
    BAD('G', INV, hfvis_sky_view_factor(&g_ok, -1, NULL, out, GW));
    BAD('R', INV, hfvis_sky_view_factor(&g_ok, 4, NULL, out, GW - 1));
    BAD('O', INV, hfvis_sky_view_factor(&g_ok, 4, NULL, out, PTRDIFF_MAX));
    GRID_CASES(hfvis_sky_view_factor(&bg, 4, NULL, out, GW));
    SWEEP_OPT_CASES(hfvis_sky_view_factor(&g_ok, 4, &bo, out, GW));
}

static void args_sky_view_factor_from_map(void)
{
    float *out;
    begin("sky_view_factor_from_map");
    out = AF(GW * GH);
    OK(hfvis_sky_view_factor_from_map(&g_ok, 4, g_map, out, GW));
    BAD('N', INV, hfvis_sky_view_factor_from_map(NULL, 4, g_map, out, GW));
    BAD('N', INV, hfvis_sky_view_factor_from_map(&g_ok, 4, NULL, out, GW));
    BAD('N', INV, hfvis_sky_view_factor_from_map(&g_ok, 4, g_map, NULL, GW));
    BAD('Z', INV, hfvis_sky_view_factor_from_map(&g_ok, 0, g_map, out, GW));
    BAD('G', INV, hfvis_sky_view_factor_from_map(&g_ok, -1, g_map, out, GW));
    BAD('R', INV, hfvis_sky_view_factor_from_map(&g_ok, 4, g_map, out, GW - 1));
    BAD('O', INV, hfvis_sky_view_factor_from_map(&g_ok, 4, g_map, out, PTRDIFF_MAX));
    GRID_CASES(hfvis_sky_view_factor_from_map(&bg, 4, g_map, out, GW));
}

static void args_sun_visibility(void)
{
    float *out;
    begin("sun_visibility");
    out = AF(GW * GH);
    OK(hfvis_sun_visibility(&g_ok, 0.3, 0.4, 0.01, NULL, out, GW));
    BAD('N', INV, hfvis_sun_visibility(NULL, 0.3, 0.4, 0.01, NULL, out, GW));
    BAD('N', INV, hfvis_sun_visibility(&g_ok, 0.3, 0.4, 0.01, NULL, NULL, GW));
    BAD('F', INV, hfvis_sun_visibility(&g_ok, (double)NAN, 0.4, 0.01, NULL, out, GW));
    BAD('F', INV, hfvis_sun_visibility(&g_ok, 0.3, (double)INFINITY, 0.01, NULL, out, GW));
    BAD('F', INV, hfvis_sun_visibility(&g_ok, 0.3, 0.4, (double)NAN, NULL, out, GW));
    BAD('G', INV, hfvis_sun_visibility(&g_ok, 0.3, 0.4, -0.01, NULL, out, GW));
    BAD('R', INV, hfvis_sun_visibility(&g_ok, 0.3, 0.4, 0.01, NULL, out, GW - 1));
    BAD('O', INV, hfvis_sun_visibility(&g_ok, 0.3, 0.4, 0.01, NULL, out, PTRDIFF_MAX));
    GRID_CASES(hfvis_sun_visibility(&bg, 0.3, 0.4, 0.01, NULL, out, GW));
    SWEEP_OPT_CASES(hfvis_sun_visibility(&g_ok, 0.3, 0.4, 0.01, &bo, out, GW));
    { /* bands across the sun: its own; every other routine refuses them */
        hfvis_sweep_options po = hfvis_sweep_options_default();
        float *map = AF(GW * GH * 4);
        po.part_index = 2;
        po.part_count = 3;
        OK(hfvis_sun_visibility(&g_ok, 0.3, 0.4, 0.01, &po, out, GW));
        po.rays = HFVIS_RAYS_EXACT;
        OK(hfvis_sun_visibility(&g_ok, 0.3, 0.4, 0.01, &po, out, GW));
        po.rays = HFVIS_RAYS_LATTICE;
        BAD('S', INV, hfvis_sky_view_factor(&g_ok, 4, &po, out, GW));
        BAD('S', INV, hfvis_horizon_direction(&g_ok, 4, 1, &po, out, GW));
        BAD('S', INV, hfvis_horizon_map(&g_ok, 4, &po, map));
        po.part_index = 0;
        po.part_count = 1; /* one band is every receiver: accepted everywhere */
        OK(hfvis_sky_view_factor(&g_ok, 4, &po, out, GW));
    }
}

static void args_env_options_default(void)
{
    hfvis_env_options o = hfvis_env_options_default();
    begin("env_options_default");
    CHECK(o.method == HFVIS_ENV_DEFAULT || o.method == HFVIS_ENV_PREFIX);
}

/* Invalid environments and environment options, substituted as &be / &bx. */
#define ENV_CASES(expr) do { hfvis_env be; \
    be = g_env; be.radiance = NULL; BAD('N', INV, expr); \
    be = g_env; be.n_theta = 0; BAD('Z', INV, expr); \
    be = g_env; be.n_phi = -1; BAD('G', INV, expr); \
    be = g_env; be.channels = 5; BAD('S', INV, expr); \
    be = g_env; be.n_theta = INT_MAX; be.n_phi = INT_MAX; be.channels = 4; BAD('O', INV, expr); \
    } while (0)
#define EOPT_CASES(expr) do { hfvis_env_options bx; \
    bx = hfvis_env_options_default(); bx.method = (hfvis_env_method)99; BAD('E', INV, expr); \
    bx = hfvis_env_options_default(); bx.method = HFVIS_ENV_LP_TABLE; bx.lp_normal_res = 4; BAD('S', INV, expr); \
    bx = hfvis_env_options_default(); bx.method = HFVIS_ENV_LP_TABLE; bx.lp_horizon_res = 1; BAD('S', INV, expr); \
    } while (0)

static void args_env_table_floats(void)
{
    hfvis_env_options e = hfvis_env_options_default();
    hfvis_env b = g_env;
    begin("env_table_floats");
    CHECK(hfvis_env_table_floats(&g_env, 4, NULL) > 0);
    BADV('N', hfvis_env_table_floats(NULL, 4, NULL) == 0);
    BADV('Z', hfvis_env_table_floats(&g_env, 0, NULL) == 0);
    BADV('G', hfvis_env_table_floats(&g_env, -1, NULL) == 0);
    e.method = (hfvis_env_method)99;
    BADV('E', hfvis_env_table_floats(&g_env, 4, &e) == 0);
    b.channels = 0;
    BADV('S', hfvis_env_table_floats(&b, 4, NULL) == 0);
    b = g_env; b.n_theta = INT_MAX; b.channels = 4;
    BADV('O', hfvis_env_table_floats(&b, INT_MAX, NULL) == 0);
}

static void args_env_table_build(void)
{
    float *t;
    begin("env_table_build");
    t = AF(hfvis_env_table_floats(&g_env, 4, NULL));
    OK(hfvis_env_table_build(&g_env, 4, 0.0, NULL, t));
    BAD('N', INV, hfvis_env_table_build(NULL, 4, 0.0, NULL, t));
    BAD('N', INV, hfvis_env_table_build(&g_env, 4, 0.0, NULL, NULL));
    BAD('Z', INV, hfvis_env_table_build(&g_env, 0, 0.0, NULL, t));
    BAD('G', INV, hfvis_env_table_build(&g_env, -1, 0.0, NULL, t));
    BAD('F', INV, hfvis_env_table_build(&g_env, 4, (double)NAN, NULL, t));
    ENV_CASES(hfvis_env_table_build(&be, 4, 0.0, NULL, t));
    EOPT_CASES(hfvis_env_table_build(&g_env, 4, 0.0, &bx, t));
}

static void args_env_light(void)
{
    float *out;
    begin("env_light");
    out = AF(GW * GH);
    OK(hfvis_env_light(&g_ok, 4, &g_env, 1.0f, NULL, NULL, out, GW));
    BAD('N', INV, hfvis_env_light(NULL, 4, &g_env, 1.0f, NULL, NULL, out, GW));
    BAD('N', INV, hfvis_env_light(&g_ok, 4, NULL, 1.0f, NULL, NULL, out, GW));
    BAD('N', INV, hfvis_env_light(&g_ok, 4, &g_env, 1.0f, NULL, NULL, NULL, GW));
    BAD('Z', INV, hfvis_env_light(&g_ok, 0, &g_env, 1.0f, NULL, NULL, out, GW));
    BAD('G', INV, hfvis_env_light(&g_ok, -4, &g_env, 1.0f, NULL, NULL, out, GW));
    BAD('F', INV, hfvis_env_light(&g_ok, 4, &g_env, (double)NAN, NULL, NULL, out, GW));
    BAD('R', INV, hfvis_env_light(&g_ok, 4, &g_env, 1.0f, NULL, NULL, out, GW - 1));
    BAD('O', INV, hfvis_env_light(&g_ok, 4, &g_env, 1.0f, NULL, NULL, out, PTRDIFF_MAX));
    GRID_CASES(hfvis_env_light(&bg, 4, &g_env, 1.0f, NULL, NULL, out, GW));
    SWEEP_OPT_CASES(hfvis_env_light(&g_ok, 4, &g_env, 1.0f, &bo, NULL, out, GW));
    ENV_CASES(hfvis_env_light(&g_ok, 4, &be, 1.0f, NULL, NULL, out, GW));
    EOPT_CASES(hfvis_env_light(&g_ok, 4, &g_env, 1.0f, NULL, &bx, out, GW));
}

static void args_env_light_from_map(void)
{
    float *out;
    begin("env_light_from_map");
    out = AF(GW * GH);
    OK(hfvis_env_light_from_map(&g_ok, 4, 0.0, g_map, &g_env, 1.0f, NULL, NULL, out, GW));
    BAD('N', INV, hfvis_env_light_from_map(NULL, 4, 0.0, g_map, &g_env, 1.0f, NULL, NULL, out, GW));
    BAD('N', INV, hfvis_env_light_from_map(&g_ok, 4, 0.0, NULL, &g_env, 1.0f, NULL, NULL, out, GW));
    BAD('N', INV, hfvis_env_light_from_map(&g_ok, 4, 0.0, g_map, NULL, 1.0f, NULL, NULL, out, GW));
    BAD('N', INV, hfvis_env_light_from_map(&g_ok, 4, 0.0, g_map, &g_env, 1.0f, NULL, NULL, NULL, GW));
    BAD('Z', INV, hfvis_env_light_from_map(&g_ok, 0, 0.0, g_map, &g_env, 1.0f, NULL, NULL, out, GW));
    BAD('G', INV, hfvis_env_light_from_map(&g_ok, -4, 0.0, g_map, &g_env, 1.0f, NULL, NULL, out, GW));
    BAD('F', INV, hfvis_env_light_from_map(&g_ok, 4, (double)NAN, g_map, &g_env, 1.0f, NULL, NULL, out, GW));
    BAD('F', INV, hfvis_env_light_from_map(&g_ok, 4, 0.0, g_map, &g_env, (double)INFINITY, NULL, NULL, out, GW));
    BAD('R', INV, hfvis_env_light_from_map(&g_ok, 4, 0.0, g_map, &g_env, 1.0f, NULL, NULL, out, GW - 1));
    BAD('O', INV, hfvis_env_light_from_map(&g_ok, 4, 0.0, g_map, &g_env, 1.0f, NULL, NULL, out, PTRDIFF_MAX));
    GRID_CASES(hfvis_env_light_from_map(&bg, 4, 0.0, g_map, &g_env, 1.0f, NULL, NULL, out, GW));
    ENV_CASES(hfvis_env_light_from_map(&g_ok, 4, 0.0, g_map, &be, 1.0f, NULL, NULL, out, GW));
    EOPT_CASES(hfvis_env_light_from_map(&g_ok, 4, 0.0, g_map, &g_env, 1.0f, &bx, NULL, out, GW));
}

static void args_light_reference(void)
{
    static const float pts[2] = {1.0f, 1.0f}, nrm[3] = {0.0f, 0.0f, 1.0f};
    hfvis_hemisphere_options h;
    float *out;
    begin("light_reference");
    out = AF(1);
    memset(&h, 0, sizeof h);
    h.azimuth_samples = 8; h.zenith_samples = 8;
    OK(hfvis_light_reference(&g_ok, NULL, 1.0f, NULL, NULL, &h, pts, nrm, 1, out));
    BAD('N', INV, hfvis_light_reference(NULL, NULL, 1.0f, NULL, NULL, &h, pts, nrm, 1, out));
    BAD('N', INV, hfvis_light_reference(&g_ok, NULL, 1.0f, NULL, NULL, &h, NULL, nrm, 1, out));
    BAD('N', INV, hfvis_light_reference(&g_ok, NULL, 1.0f, NULL, NULL, &h, pts, NULL, 1, out));
    BAD('N', INV, hfvis_light_reference(&g_ok, NULL, 1.0f, NULL, NULL, &h, pts, nrm, 1, NULL));
    BAD('O', INV, hfvis_light_reference(&g_ok, NULL, 1.0f, NULL, NULL, &h, pts, nrm, SIZE_MAX / 2, out));
    BAD('F', INV, hfvis_light_reference(&g_ok, NULL, (double)NAN, NULL, NULL, &h, pts, nrm, 1, out));
    h.azimuth_samples = -1;
    BAD('S', INV, hfvis_light_reference(&g_ok, NULL, 1.0f, NULL, NULL, &h, pts, nrm, 1, out));
    h.azimuth_samples = 8;
    GRID_CASES(hfvis_light_reference(&bg, NULL, 1.0f, NULL, NULL, &h, pts, nrm, 1, out));
    {   /* only the border fields of opts are used (azimuth0 and progress are documented unused) */
        hfvis_sweep_options bo = hfvis_sweep_options_default();
        bo.border = (hfvis_border)99;
        BAD('E', INV, hfvis_light_reference(&g_ok, NULL, 1.0f, &bo, NULL, &h, pts, nrm, 1, out));
        bo = hfvis_sweep_options_default(); bo.border_cells = -1;
        BAD('S', INV, hfvis_light_reference(&g_ok, NULL, 1.0f, &bo, NULL, &h, pts, nrm, 1, out));
    }
    ENV_CASES(hfvis_light_reference(&g_ok, &be, 1.0f, NULL, NULL, &h, pts, nrm, 1, out));
}

/* ---- P2: hull tree, visible sets, intervisibility, indirect light ------------------------ */

#define TREE_OPT_CASES(expr) do { hfvis_tree_options bt; \
    memset(&bt, 0, sizeof bt); bt.order = (hfvis_tree_order)99; BAD('E', INV, expr); \
    memset(&bt, 0, sizeof bt); bt.safe_zone = 2; BAD('S', INV, expr); \
    memset(&bt, 0, sizeof bt); bt.safe_zone_steps = -1; BAD('S', INV, expr); \
    } while (0)

static void args_hull_tree_size(void)
{
    begin("hull_tree_size");
    CHECK(hfvis_hull_tree_size(4) > 0);
    BADV('Z', hfvis_hull_tree_size(0) == 0);
    BADV('G', hfvis_hull_tree_size(-1) == 0);
}

static double tree_mem[512];

static void args_hull_tree_init(void)
{
    size_t need = hfvis_hull_tree_size(4);
    hfvis_hull_tree **t;
    void *mem;
    begin("hull_tree_init");
    mem = out_bytes(need);
    t = AT(hfvis_hull_tree *);
    OK(hfvis_hull_tree_init(mem, need, 4, NULL, t));
    BAD('N', INV, hfvis_hull_tree_init(NULL, need, 4, NULL, t));
    BAD('N', INV, hfvis_hull_tree_init(mem, need, 4, NULL, NULL));
    BAD('Z', INV, hfvis_hull_tree_init(mem, need, 0, NULL, t));
    BAD('G', INV, hfvis_hull_tree_init(mem, need, -1, NULL, t));
    BAD('R', SMALL, hfvis_hull_tree_init(mem, need - 1, 4, NULL, t));
    BAD('O', SMALL, hfvis_hull_tree_init(mem, need, INT_MAX, NULL, t));
    TREE_OPT_CASES(hfvis_hull_tree_init(mem, need, 4, &bt, t));
}

static hfvis_hull_tree *tree_with_two(void)
{
    hfvis_hull_tree *t = NULL;
    if (hfvis_hull_tree_init(tree_mem, sizeof tree_mem, 2, NULL, &t) != HFVIS_OK) return NULL;
    hfvis_hull_tree_push(t, 0.0, 1.0, NULL);
    hfvis_hull_tree_push(t, 1.0, 0.0, NULL);
    return t;
}

static void args_hull_tree_reset(void)
{
    hfvis_hull_tree *t = tree_with_two();
    begin("hull_tree_reset");
    hfvis_hull_tree_reset(NULL);
    hfvis_hull_tree_reset(t);
    BADV('N', hfvis_hull_tree_count(t) == 0);
}

static void args_hull_tree_push(void)
{
    size_t need = hfvis_hull_tree_size(3);
    hfvis_hull_tree *t = NULL;
    void *mem;
    int *hc;
    begin("hull_tree_push");
    hc = AT(int);
    mem = out_bytes(need); /* the tree is an in/out argument: a failing push must not change it */
    arena_fill();
    CHECK(hfvis_hull_tree_init(mem, need, 3, NULL, &t) == HFVIS_OK);
    base_status(hfvis_hull_tree_push(t, 0.0, 1.0, hc), __LINE__);
#define TREE_TWO (hfvis_hull_tree_init(mem, need, 3, NULL, &t), hfvis_hull_tree_push(t, 0.0, 1.0, NULL), \
                  hfvis_hull_tree_push(t, 1.0, 0.5, NULL))
    BADP('N', INV, TREE_TWO, hfvis_hull_tree_push(NULL, 2.0, 1.0, hc));
    BADP('F', INV, TREE_TWO, hfvis_hull_tree_push(t, (double)NAN, 1.0, hc));
    BADP('F', INV, TREE_TWO, hfvis_hull_tree_push(t, 2.0, (double)INFINITY, hc));
    BADP('R', INV, TREE_TWO, hfvis_hull_tree_push(t, 1.0, 1.0, hc));
    BADP('R', INV, TREE_TWO, hfvis_hull_tree_push(t, 0.5, 1.0, hc));
    BADP('O', LIM, (TREE_TWO, hfvis_hull_tree_push(t, 2.0, 0.0, NULL)), hfvis_hull_tree_push(t, 3.0, 0.0, hc));
#undef TREE_TWO
    CHECK(hfvis_hull_tree_count(t) == 3); /* the full tree the LIMIT case was given is intact */
}

static void args_hull_tree_horizons(void)
{
    hfvis_hull_tree *t = tree_with_two();
    int *out;
    begin("hull_tree_horizons");
    out = ATN(int, 2);
    CHECK(t && hfvis_hull_tree_horizons(t, 0, NULL, 0) >= 0);
    BADV('N', hfvis_hull_tree_horizons(NULL, 0, out, 2) == -1);
    BADV('N', hfvis_hull_tree_horizons(t, 0, NULL, 2) == -1);
    BADV('G', hfvis_hull_tree_horizons(t, 0, out, -1) == -1);
}

static void args_hull_tree_count(void)
{
    hfvis_hull_tree *t = tree_with_two();
    begin("hull_tree_count");
    CHECK(hfvis_hull_tree_count(t) == 2);
    BADV('N', hfvis_hull_tree_count(NULL) == 0);
}

static void args_hull_tree_iterations(void)
{
    hfvis_hull_tree *t = tree_with_two();
    begin("hull_tree_iterations");
    CHECK(hfvis_hull_tree_iterations(t) >= 0);
    BADV('N', hfvis_hull_tree_iterations(NULL) == 0);
}

static const double ln_d[4] = {0, 1, 2, 3}, ln_h[4] = {2, 0, 1, 0};

static void args_line_visible_from_horizons(void)
{
    static const int hz[2] = {0, 2};
    int *out;
    begin("line_visible_from_horizons");
    out = ATN(int, 4);
    CHECK(hfvis_line_visible_from_horizons(ln_d, ln_h, 3, hz, 2, NULL, 0) >= 0);
    BADV('N', hfvis_line_visible_from_horizons(NULL, ln_h, 3, hz, 2, out, 4) == -1);
    BADV('N', hfvis_line_visible_from_horizons(ln_d, NULL, 3, hz, 2, out, 4) == -1);
    BADV('N', hfvis_line_visible_from_horizons(ln_d, ln_h, 3, NULL, 2, out, 4) == -1);
    BADV('N', hfvis_line_visible_from_horizons(ln_d, ln_h, 3, hz, 2, NULL, 4) == -1);
    BADV('G', hfvis_line_visible_from_horizons(ln_d, ln_h, -1, hz, 2, out, 4) == -1);
    BADV('G', hfvis_line_visible_from_horizons(ln_d, ln_h, 3, hz, -1, out, 4) == -1);
    BADV('G', hfvis_line_visible_from_horizons(ln_d, ln_h, 3, hz, 2, out, -1) == -1);
}

static void args_line_visible_naive(void)
{
    int *out;
    begin("line_visible_naive");
    out = ATN(int, 4);
    CHECK(hfvis_line_visible_naive(ln_d, ln_h, 3, NULL, 0) >= 0);
    BADV('N', hfvis_line_visible_naive(NULL, ln_h, 3, out, 4) == -1);
    BADV('N', hfvis_line_visible_naive(ln_d, NULL, 3, out, 4) == -1);
    BADV('N', hfvis_line_visible_naive(ln_d, ln_h, 3, NULL, 4) == -1);
    BADV('G', hfvis_line_visible_naive(ln_d, ln_h, -1, out, 4) == -1);
    BADV('G', hfvis_line_visible_naive(ln_d, ln_h, 3, out, -1) == -1);
}

static void args_line_local_horizons_naive(void)
{
    int *out;
    begin("line_local_horizons_naive");
    out = ATN(int, 4);
    CHECK(hfvis_line_local_horizons_naive(ln_d, ln_h, 3, NULL, 0) >= 0);
    BADV('N', hfvis_line_local_horizons_naive(NULL, ln_h, 3, out, 4) == -1);
    BADV('N', hfvis_line_local_horizons_naive(ln_d, NULL, 3, out, 4) == -1);
    BADV('N', hfvis_line_local_horizons_naive(ln_d, ln_h, 3, NULL, 4) == -1);
    BADV('G', hfvis_line_local_horizons_naive(ln_d, ln_h, -1, out, 4) == -1);
    BADV('G', hfvis_line_local_horizons_naive(ln_d, ln_h, 3, out, -1) == -1);
}

static void vis_cb(void *user, const hfvis_visibility_event *e)
{
    (void)e;
    (*(int *)user)++;
}

static void args_intervisibility(void)
{
    hfvis_visibility_stats *st;
    int calls = 0;
    begin("intervisibility");
    st = AT(hfvis_visibility_stats);
    OK(hfvis_intervisibility(&g_ok, 4, NULL, NULL, vis_cb, &calls, st));
    P2_RADIUS_CASES(hfvis_intervisibility(&g_ok, 4, &bo, NULL, vis_cb, &calls, st)); /* calls: OK rows */
    calls = 0;
    BAD('N', INV, hfvis_intervisibility(NULL, 4, NULL, NULL, vis_cb, &calls, st));
    BAD('N', INV, hfvis_intervisibility(&g_ok, 4, NULL, NULL, NULL, &calls, st));
    BAD('Z', INV, hfvis_intervisibility(&g_ok, 0, NULL, NULL, vis_cb, &calls, st));
    BAD('G', INV, hfvis_intervisibility(&g_ok, -1, NULL, NULL, vis_cb, &calls, st));
    GRID_CASES(hfvis_intervisibility(&bg, 4, NULL, NULL, vis_cb, &calls, st));
    SWEEP_OPT_CASES(hfvis_intervisibility(&g_ok, 4, &bo, NULL, vis_cb, &calls, st));
    TREE_OPT_CASES(hfvis_intervisibility(&g_ok, 4, NULL, &bt, vis_cb, &calls, st));
    BADV('N', calls == 0);
}

static void args_visibility_count(void)
{
    hfvis_visibility_stats *st;
    float *out;
    begin("visibility_count");
    out = AF(GW * GH);
    st = AT(hfvis_visibility_stats);
    OK(hfvis_visibility_count(&g_ok, 4, NULL, NULL, out, GW, st));
    BAD('N', INV, hfvis_visibility_count(NULL, 4, NULL, NULL, out, GW, st));
    BAD('N', INV, hfvis_visibility_count(&g_ok, 4, NULL, NULL, NULL, GW, st));
    BAD('Z', INV, hfvis_visibility_count(&g_ok, 0, NULL, NULL, out, GW, st));
    BAD('G', INV, hfvis_visibility_count(&g_ok, -1, NULL, NULL, out, GW, st));
    BAD('R', INV, hfvis_visibility_count(&g_ok, 4, NULL, NULL, out, GW - 1, st));
    BAD('O', INV, hfvis_visibility_count(&g_ok, 4, NULL, NULL, out, PTRDIFF_MAX, st));
    GRID_CASES(hfvis_visibility_count(&bg, 4, NULL, NULL, out, GW, st));
    SWEEP_OPT_CASES(hfvis_visibility_count(&g_ok, 4, &bo, NULL, out, GW, st));
    P2_RADIUS_CASES(hfvis_visibility_count(&g_ok, 4, &bo, NULL, out, GW, st));
    TREE_OPT_CASES(hfvis_visibility_count(&g_ok, 4, NULL, &bt, out, GW, st));
}

static void args_visibility_count_naive(void)
{
    hfvis_visibility_stats *st;
    float *out;
    begin("visibility_count_naive");
    out = AF(GW * GH);
    st = AT(hfvis_visibility_stats);
    OK(hfvis_visibility_count_naive(&g_ok, 4, NULL, out, GW, st));
    BAD('N', INV, hfvis_visibility_count_naive(NULL, 4, NULL, out, GW, st));
    BAD('N', INV, hfvis_visibility_count_naive(&g_ok, 4, NULL, NULL, GW, st));
    BAD('Z', INV, hfvis_visibility_count_naive(&g_ok, 0, NULL, out, GW, st));
    BAD('G', INV, hfvis_visibility_count_naive(&g_ok, -1, NULL, out, GW, st));
    BAD('R', INV, hfvis_visibility_count_naive(&g_ok, 4, NULL, out, GW - 1, st));
    BAD('O', INV, hfvis_visibility_count_naive(&g_ok, 4, NULL, out, PTRDIFF_MAX, st));
    GRID_CASES(hfvis_visibility_count_naive(&bg, 4, NULL, out, GW, st));
    SWEEP_OPT_CASES(hfvis_visibility_count_naive(&g_ok, 4, &bo, out, GW, st));
    P2_RADIUS_CASES(hfvis_visibility_count_naive(&g_ok, 4, &bo, out, GW, st));
}

static float ex_rad[GW * GH * 2];

/* Solar radiation: one valid instant and site, then each invalid field. */
static hfvis_spa_input spa_ok(void)
{
    hfvis_spa_input in;
    memset(&in, 0, sizeof in);
    in.year = 2026; in.month = 6; in.day = 21; in.hour = 12;
    in.delta_t = 69.0;
    in.latitude_rad = 0.8; in.longitude_rad = 0.2;
    return in;
}

static void args_spa(void)
{
    hfvis_spa_input in = spa_ok(), b;
    hfvis_spa_result *r;
    begin("spa");
    r = (hfvis_spa_result *)out_bytes(sizeof *r);
    OK(hfvis_spa(&in, r));
    BAD('N', INV, hfvis_spa(NULL, r));
    BAD('N', INV, hfvis_spa(&in, NULL));
    b = in; b.minute = -1; BAD('G', INV, hfvis_spa(&b, r));
    b = in; b.second = (double)NAN; BAD('F', INV, hfvis_spa(&b, r));
    b = in; b.delta_t = (double)INFINITY; BAD('F', INV, hfvis_spa(&b, r));
    b = in; b.month = 13; BAD('R', INV, hfvis_spa(&b, r));
    b = in; b.month = 2; b.day = 30; BAD('R', INV, hfvis_spa(&b, r));
    b = in; b.latitude_rad = 1.6; BAD('R', INV, hfvis_spa(&b, r));
    b = in; b.refraction = 1; b.pressure_mbar = 0.0; BAD('R', INV, hfvis_spa(&b, r));
}

static void args_rsun_sun_position(void)
{
    hfvis_rsun_sun *r;
    begin("rsun_sun_position");
    r = (hfvis_rsun_sun *)out_bytes(sizeof *r);
    OK(hfvis_rsun_sun_position(172, 12.0, 0.8, r));
    BAD('N', INV, hfvis_rsun_sun_position(172, 12.0, 0.8, NULL));
    BAD('Z', INV, hfvis_rsun_sun_position(0, 12.0, 0.8, r));
    BAD('G', INV, hfvis_rsun_sun_position(-1, 12.0, 0.8, r));
    BAD('F', INV, hfvis_rsun_sun_position(172, (double)NAN, 0.8, r));
    BAD('R', INV, hfvis_rsun_sun_position(367, 12.0, 0.8, r));
    BAD('R', INV, hfvis_rsun_sun_position(172, 12.0, 1.6, r));
}

static void args_esra_clear_sky(void)
{
    double *r;
    begin("esra_clear_sky");
    r = (double *)out_bytes(3 * sizeof *r);
    OK(hfvis_esra_clear_sky(1367.0, 0.5, 100.0, 3.0, r));
    BAD('N', INV, hfvis_esra_clear_sky(1367.0, 0.5, 100.0, 3.0, NULL));
    BAD('G', INV, hfvis_esra_clear_sky(-1.0, 0.5, 100.0, 3.0, r));
    BAD('F', INV, hfvis_esra_clear_sky(1367.0, (double)NAN, 100.0, 3.0, r));
    BAD('F', INV, hfvis_esra_clear_sky(1367.0, 0.5, (double)INFINITY, 3.0, r));
    BAD('R', INV, hfvis_esra_clear_sky(1367.0, 0.5, 100.0, 10.5, r));
    BAD('R', INV, hfvis_esra_clear_sky(1367.0, 0.5, 100.0, 0.0, r));
}

static void args_solar_input_default(void)
{
    hfvis_solar_input in = hfvis_solar_input_default();
    begin("solar_input_default");
    CHECK(in.linke == 3.0 && in.albedo == 0.2 && in.days == 1 && in.instant == 0);
}

static void args_solar_options_default(void)
{
    hfvis_solar_options o = hfvis_solar_options_default();
    begin("solar_options_default");
    CHECK(o.model == HFVIS_SUN_SPA && o.step_hours == 0.25 && o.directions == 64 && o.sweep == NULL);
}

static void args_solar_map_options(void)
{
    hfvis_solar_options o = hfvis_solar_options_default();
    hfvis_sweep_options s = hfvis_solar_map_options(NULL);
    begin("solar_map_options");
    CHECK(s.rays == HFVIS_RAYS_EXACT && s.ray_near_cells == 0 && s.direction_end == 0);
    o.horizons = HFVIS_SOLAR_HORIZONS_LATTICE;
    s = hfvis_solar_map_options(&o);
    CHECK(s.rays == HFVIS_RAYS_LATTICE);
    o.horizons = (hfvis_solar_horizons)99; /* not checked here: hfvis_solar_irradiation refuses it */
    s = hfvis_solar_map_options(&o);
    CHECK(s.rays == HFVIS_RAYS_EXACT);
}

static hfvis_solar_input solar_in_ok(void)
{
    hfvis_solar_input in = hfvis_solar_input_default();
    in.latitude_rad = 0.8;
    in.longitude_rad = 0.2;
    return in;
}

static void args_solar_band_count(void)
{
    hfvis_solar_input in = solar_in_ok(), b;
    hfvis_solar_options o = hfvis_solar_options_default();
    begin("solar_band_count");
    BADV('N', hfvis_solar_band_count(NULL, NULL) == -1);
    b = in; b.days = 0; BADV('Z', hfvis_solar_band_count(&b, NULL) == -1);
    o.bands = (hfvis_solar_bands)9; BADV('E', hfvis_solar_band_count(&in, &o) == -1);
    o.bands = HFVIS_SOLAR_BANDS_DEFAULT;
    o.normals = (hfvis_solar_normals)5; BADV('E', hfvis_solar_band_count(&in, &o) == -1);
    CHECK(hfvis_solar_band_count(&in, NULL) == 1);
}

typedef hfvis_status (*solar_fn)(const hfvis_grid *, const hfvis_solar_input *,
                                 const hfvis_solar_options *, const hfvis_solar_output *);

/* hfvis_solar_input.site: raster cell (x, y) 0.01 rad apart per cell; *user = 1 puts cell (0, 0)
 * beyond the pole (out of range). */
static void solar_site_fn(void *user, int x, int y, double *lat, double *lon)
{
    *lat = (user && *(const int *)user ? 1.6 : 0.8) - 0.01 * (double)y;
    *lon = 0.2 + 0.01 * (double)x;
}

static void solar_args(const char *name, solar_fn fn)
{
    hfvis_solar_input in = solar_in_ok(), b;
    hfvis_solar_options o = hfvis_solar_options_default(), bo2;
    hfvis_solar_output out, none;
    static float lk[GW * GH], monthly[12];
    int i;
    begin(name);
    memset(&out, 0, sizeof out);
    memset(&none, 0, sizeof none);
    out.global = AF(GW * GH);
    out.sun_hours = AF(GW * GH);
    o.directions = 8;
    for (i = 0; i < GW * GH; i++) lk[i] = 3.0f;
    for (i = 0; i < 12; i++) monthly[i] = 3.0f;
    OK(fn(&g_ok, &in, &o, &out));
    BAD('N', INV, fn(&g_ok, NULL, &o, &out));
    BAD('N', INV, fn(&g_ok, &in, &o, NULL));
    BAD('N', INV, fn(&g_ok, &in, &o, &none));
    b = in; b.days = 0; BAD('Z', INV, fn(&g_ok, &b, &o, &out));
    b = in; b.albedo = -0.1; BAD('G', INV, fn(&g_ok, &b, &o, &out));
    b = in; b.latitude_rad = (double)NAN; BAD('F', INV, fn(&g_ok, &b, &o, &out));
    b = in; b.month = 2; b.day = 29; BAD('R', INV, fn(&g_ok, &b, &o, &out));
    b = in; b.linke = 10.5; BAD('R', INV, fn(&g_ok, &b, &o, &out));
    b = in; b.albedo = 1.5; BAD('R', INV, fn(&g_ok, &b, &o, &out));
    b = in; b.latitude_rad = 1.6; BAD('R', INV, fn(&g_ok, &b, &o, &out));
    b = in; b.days = 36601; BAD('O', INV, fn(&g_ok, &b, &o, &out));
    bo2 = o; bo2.model = (hfvis_sun_model)7; BAD('E', INV, fn(&g_ok, &in, &bo2, &out));
    bo2 = o; bo2.diffuse = (hfvis_solar_diffuse)7; BAD('E', INV, fn(&g_ok, &in, &bo2, &out));
    bo2 = o; bo2.horizons = (hfvis_solar_horizons)7; BAD('E', INV, fn(&g_ok, &in, &bo2, &out));
    bo2 = o; bo2.row_begin = 3; bo2.row_end = 2; BAD('S', INV, fn(&g_ok, &in, &bo2, &out));
    bo2 = o; bo2.normals = (hfvis_solar_normals)2; BAD('E', INV, fn(&g_ok, &in, &bo2, &out));
    bo2 = o; bo2.normals = (hfvis_solar_normals)-1; BAD('E', INV, fn(&g_ok, &in, &bo2, &out));
    bo2 = o; bo2.step_hours = -0.25; BAD('S', INV, fn(&g_ok, &in, &bo2, &out));
    bo2 = o; bo2.sun_radius_rad = 1.0; BAD('S', INV, fn(&g_ok, &in, &bo2, &out));
    bo2 = o; bo2.directions = -1; BAD('S', INV, fn(&g_ok, &in, &bo2, &out));
    bo2 = o; lk[5] = 0.0f; bo2.linke_map = lk; BAD('S', INV, fn(&g_ok, &in, &bo2, &out));
    lk[5] = 3.0f;
    bo2 = o; monthly[3] = 11.0f; bo2.linke_monthly = monthly; BAD('S', INV, fn(&g_ok, &in, &bo2, &out));
    monthly[3] = 3.0f;
    GRID_CASES(fn(&bg, &in, &o, &out));
    {
        hfvis_sweep_options bo;
        bo2 = o;
        bo2.sweep = &bo;
        bo = hfvis_sweep_options_default(); bo.border = (hfvis_border)99; BAD('E', INV, fn(&g_ok, &in, &bo2, &out));
        bo = hfvis_sweep_options_default(); bo.max_distance = -1.0; BAD('S', INV, fn(&g_ok, &in, &bo2, &out));
        static double lmap[GW * GH];
        static int beyond_pole = 1;
        for (i = 0; i < GW * GH; i++) lmap[i] = 0.5;
        bo = hfvis_sweep_options_default(); bo.receiver_width = bo.receiver_height = 1; OK(fn(&g_ok, &in, &bo2, &out));
        bo2.reflected = HFVIS_SOLAR_REFLECTED_TERRAIN; BAD('S', INV, fn(&g_ok, &in, &bo2, &out)); /* gathers the grid */
        bo2.reflected = HFVIS_SOLAR_REFLECTED_DEFAULT;
        bo = hfvis_sweep_options_default(); bo.max_distance = 3.0; bo.origin_x = 2; bo.extent_width = GW + 2;
        bo.extent_height = GH; b = in; b.site = solar_site_fn; OK(fn(&g_ok, &b, &bo2, &out));
        b.latitude_map = b.longitude_map = lmap; BAD('S', INV, fn(&g_ok, &b, &bo2, &out)); /* maps and site */
        b.site = NULL; BAD('S', INV, fn(&g_ok, &b, &bo2, &out)); /* maps of a window */
        bo.max_distance = 0.0; b = in; b.site = solar_site_fn; BAD('S', INV, fn(&g_ok, &b, &bo2, &out)); /* no R */
        b.site_user = &beyond_pole; BAD('R', INV, fn(&g_ok, &b, &o, &out));
    }
    bo2 = o; bo2.height_min = 5.0; bo2.height_max = 4.0; BAD('R', INV, fn(&g_ok, &in, &bo2, &out));
    bo2 = o; bo2.height_max = (double)NAN; BAD('F', INV, fn(&g_ok, &in, &bo2, &out));
    bo2 = o; bo2.height_min = -(double)INFINITY; BAD('F', INV, fn(&g_ok, &in, &bo2, &out));
}

/* hfvis_solar_map_directions through solar_args: the global output's floats stand for need (NULL
 * when no output is given), so every class solar_irradiation refuses is checked for it too. */
static hfvis_status solar_directions(const hfvis_grid *g, const hfvis_solar_input *in,
                                     const hfvis_solar_options *o, const hfvis_solar_output *out)
{
    return hfvis_solar_map_directions(g, in, o, out && out->global ? (unsigned char *)(void *)out->global : NULL);
}
static void args_solar_map_directions(void) { solar_args("solar_map_directions", solar_directions); }
static void args_solar_irradiation(void) { solar_args("solar_irradiation", hfvis_solar_irradiation); }
static void args_solar_irradiation_reference(void)
{
    solar_args("solar_irradiation_reference", hfvis_solar_irradiation_reference);
}

static void args_indirect_light(void)
{
    float *out;
    begin("indirect_light");
    out = AF(GW * GH);
    OK(hfvis_indirect_light(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, NULL, NULL, out, GW));
    BAD('N', INV, hfvis_indirect_light(NULL, 4, ex_rad, 1, 1.0f, 0.5f, NULL, NULL, out, GW));
    BAD('N', INV, hfvis_indirect_light(&g_ok, 4, NULL, 1, 1.0f, 0.5f, NULL, NULL, out, GW));
    BAD('N', INV, hfvis_indirect_light(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, NULL, NULL, NULL, GW));
    BAD('Z', INV, hfvis_indirect_light(&g_ok, 0, ex_rad, 1, 1.0f, 0.5f, NULL, NULL, out, GW));
    BAD('Z', INV, hfvis_indirect_light(&g_ok, 4, ex_rad, 0, 1.0f, 0.5f, NULL, NULL, out, GW));
    BAD('G', INV, hfvis_indirect_light(&g_ok, -4, ex_rad, 1, 1.0f, 0.5f, NULL, NULL, out, GW));
    BAD('R', INV, hfvis_indirect_light(&g_ok, 4, ex_rad, 5, 1.0f, 0.5f, NULL, NULL, out, GW));
    BAD('F', INV, hfvis_indirect_light(&g_ok, 4, ex_rad, 1, (double)NAN, 0.5f, NULL, NULL, out, GW));
    BAD('F', INV, hfvis_indirect_light(&g_ok, 4, ex_rad, 1, 1.0f, (double)INFINITY, NULL, NULL, out, GW));
    BAD('R', INV, hfvis_indirect_light(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, NULL, NULL, out, GW - 1));
    BAD('O', INV, hfvis_indirect_light(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, NULL, NULL, out, PTRDIFF_MAX));
    GRID_CASES(hfvis_indirect_light(&bg, 4, ex_rad, 1, 1.0f, 0.5f, NULL, NULL, out, GW));
    SWEEP_OPT_CASES(hfvis_indirect_light(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, &bo, NULL, out, GW));
    P2_RADIUS_CASES(hfvis_indirect_light(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, &bo, NULL, out, GW));
    TREE_OPT_CASES(hfvis_indirect_light(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, NULL, &bt, out, GW));
}

static void args_indirect_light_naive(void)
{
    float *out;
    begin("indirect_light_naive");
    out = AF(GW * GH);
    OK(hfvis_indirect_light_naive(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, NULL, out, GW));
    BAD('N', INV, hfvis_indirect_light_naive(NULL, 4, ex_rad, 1, 1.0f, 0.5f, NULL, out, GW));
    BAD('N', INV, hfvis_indirect_light_naive(&g_ok, 4, NULL, 1, 1.0f, 0.5f, NULL, out, GW));
    BAD('N', INV, hfvis_indirect_light_naive(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, NULL, NULL, GW));
    BAD('Z', INV, hfvis_indirect_light_naive(&g_ok, 0, ex_rad, 1, 1.0f, 0.5f, NULL, out, GW));
    BAD('G', INV, hfvis_indirect_light_naive(&g_ok, 4, ex_rad, -1, 1.0f, 0.5f, NULL, out, GW));
    BAD('R', INV, hfvis_indirect_light_naive(&g_ok, 4, ex_rad, 5, 1.0f, 0.5f, NULL, out, GW));
    BAD('F', INV, hfvis_indirect_light_naive(&g_ok, 4, ex_rad, 1, (double)INFINITY, 0.5f, NULL, out, GW));
    BAD('F', INV, hfvis_indirect_light_naive(&g_ok, 4, ex_rad, 1, 1.0f, (double)NAN, NULL, out, GW));
    BAD('R', INV, hfvis_indirect_light_naive(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, NULL, out, GW - 1));
    BAD('O', INV, hfvis_indirect_light_naive(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, NULL, out, PTRDIFF_MAX));
    GRID_CASES(hfvis_indirect_light_naive(&bg, 4, ex_rad, 1, 1.0f, 0.5f, NULL, out, GW));
    SWEEP_OPT_CASES(hfvis_indirect_light_naive(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, &bo, out, GW));
    P2_RADIUS_CASES(hfvis_indirect_light_naive(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, &bo, out, GW));
}

static void args_terrain_gi(void)
{
    float *out;
    begin("terrain_gi");
    out = AF(GW * GH);
    OK(hfvis_terrain_gi(&g_ok, 4, ex_rad, NULL, NULL, 0.5f, 1, 1, NULL, NULL, out));
    BAD('N', INV, hfvis_terrain_gi(NULL, 4, ex_rad, NULL, NULL, 0.5f, 1, 1, NULL, NULL, out));
    BAD('N', INV, hfvis_terrain_gi(&g_ok, 4, NULL, NULL, NULL, 0.5f, 1, 1, NULL, NULL, out));
    BAD('N', INV, hfvis_terrain_gi(&g_ok, 4, ex_rad, NULL, NULL, 0.5f, 1, 1, NULL, NULL, NULL));
    BAD('Z', INV, hfvis_terrain_gi(&g_ok, 0, ex_rad, NULL, NULL, 0.5f, 1, 1, NULL, NULL, out));
    BAD('Z', INV, hfvis_terrain_gi(&g_ok, 4, ex_rad, NULL, NULL, 0.5f, 0, 1, NULL, NULL, out));
    BAD('G', INV, hfvis_terrain_gi(&g_ok, 4, ex_rad, NULL, NULL, 0.5f, 1, -1, NULL, NULL, out));
    BAD('R', INV, hfvis_terrain_gi(&g_ok, 4, ex_rad, NULL, NULL, 0.5f, 5, 1, NULL, NULL, out));
    BAD('F', INV, hfvis_terrain_gi(&g_ok, 4, ex_rad, NULL, NULL, (double)NAN, 1, 1, NULL, NULL, out));
    GRID_CASES(hfvis_terrain_gi(&bg, 4, ex_rad, NULL, NULL, 0.5f, 1, 1, NULL, NULL, out));
    SWEEP_OPT_CASES(hfvis_terrain_gi(&g_ok, 4, ex_rad, NULL, NULL, 0.5f, 1, 1, &bo, NULL, out));
    P2_RADIUS_CASES(hfvis_terrain_gi(&g_ok, 4, ex_rad, NULL, NULL, 0.5f, 1, 1, &bo, NULL, out));
    TREE_OPT_CASES(hfvis_terrain_gi(&g_ok, 4, ex_rad, NULL, NULL, 0.5f, 1, 1, NULL, &bt, out));
}

static void args_direct_light(void)
{
    hfvis_sun sun, b;
    float *out;
    begin("direct_light");
    out = AF(GW * GH);
    memset(&sun, 0, sizeof sun);
    sun.azimuth_rad = 0.3; sun.elevation_rad = 0.5; sun.radius_rad = 0.01; sun.irradiance[0] = 1.0f;
    OK(hfvis_direct_light(&g_ok, 4, &sun, 1.0f, NULL, 1, NULL, out));
    OK(hfvis_direct_light(&g_ok, 4, &sun, 1.0f, &g_env, 1, NULL, out));
    BAD('N', INV, hfvis_direct_light(NULL, 4, &sun, 1.0f, NULL, 1, NULL, out));
    BAD('N', INV, hfvis_direct_light(&g_ok, 4, &sun, 1.0f, NULL, 1, NULL, NULL));
    BAD('Z', INV, hfvis_direct_light(&g_ok, 0, &sun, 1.0f, NULL, 1, NULL, out));
    BAD('Z', INV, hfvis_direct_light(&g_ok, 4, &sun, 1.0f, NULL, 0, NULL, out));
    BAD('G', INV, hfvis_direct_light(&g_ok, -4, &sun, 1.0f, NULL, 1, NULL, out));
    BAD('R', INV, hfvis_direct_light(&g_ok, 4, &sun, 1.0f, NULL, 5, NULL, out));
    BAD('R', INV, hfvis_direct_light(&g_ok, 4, &sun, 1.0f, &g_env, 2, NULL, out));
    BAD('F', INV, hfvis_direct_light(&g_ok, 4, &sun, (double)NAN, NULL, 1, NULL, out));
    b = sun; b.azimuth_rad = (double)NAN; BAD('S', INV, hfvis_direct_light(&g_ok, 4, &b, 1.0f, NULL, 1, NULL, out));
    b = sun; b.radius_rad = -1.0; BAD('S', INV, hfvis_direct_light(&g_ok, 4, &b, 1.0f, NULL, 1, NULL, out));
    b = sun; b.irradiance[0] = (double)INFINITY; BAD('S', INV, hfvis_direct_light(&g_ok, 4, &b, 1.0f, NULL, 1, NULL, out));
    GRID_CASES(hfvis_direct_light(&bg, 4, &sun, 1.0f, NULL, 1, NULL, out));
    SWEEP_OPT_CASES(hfvis_direct_light(&g_ok, 4, &sun, 1.0f, NULL, 1, &bo, out));
    ENV_CASES(hfvis_direct_light(&g_ok, 4, &sun, 1.0f, &be, 1, NULL, out));
}

#define VIEWSHED_OPT_CASES(expr) do { hfvis_viewshed_options bv; \
    memset(&bv, 0, sizeof bv); bv.observer_height = -1.0; BAD('S', INV, expr); \
    memset(&bv, 0, sizeof bv); bv.target_height = (double)NAN; BAD('S', INV, expr); \
    memset(&bv, 0, sizeof bv); bv.max_distance = -(double)INFINITY; BAD('S', INV, expr); \
    memset(&bv, 0, sizeof bv); bv.max_distance = (double)INFINITY; BAD('S', INV, expr); \
    } while (0)

static void args_viewshed(void)
{
    float *out;
    begin("viewshed");
    out = AF(GW * GH);
    OK(hfvis_viewshed(&g_ok, 1.0, 1.0, NULL, out, GW));
    BAD('N', INV, hfvis_viewshed(NULL, 1.0, 1.0, NULL, out, GW));
    BAD('N', INV, hfvis_viewshed(&g_ok, 1.0, 1.0, NULL, NULL, GW));
    BAD('F', INV, hfvis_viewshed(&g_ok, (double)NAN, 1.0, NULL, out, GW));
    BAD('F', INV, hfvis_viewshed(&g_ok, 1.0, (double)INFINITY, NULL, out, GW));
    BAD('G', INV, hfvis_viewshed(&g_ok, -0.5, 1.0, NULL, out, GW));
    BAD('R', INV, hfvis_viewshed(&g_ok, 1.0, GH, NULL, out, GW));
    BAD('R', INV, hfvis_viewshed(&g_ok, 1.0, 1.0, NULL, out, GW - 1));
    BAD('O', INV, hfvis_viewshed(&g_ok, 1.0, 1.0, NULL, out, PTRDIFF_MAX));
    GRID_CASES(hfvis_viewshed(&bg, 1.0, 1.0, NULL, out, GW));
    VIEWSHED_OPT_CASES(hfvis_viewshed(&g_ok, 1.0, 1.0, &bv, out, GW));
}

static void args_viewshed_reference(void)
{
    float *out;
    begin("viewshed_reference");
    out = AF(GW * GH);
    OK(hfvis_viewshed_reference(&g_ok, 1.0, 1.0, NULL, 0.5, out, GW));
    BAD('N', INV, hfvis_viewshed_reference(NULL, 1.0, 1.0, NULL, 0.5, out, GW));
    BAD('N', INV, hfvis_viewshed_reference(&g_ok, 1.0, 1.0, NULL, 0.5, NULL, GW));
    BAD('F', INV, hfvis_viewshed_reference(&g_ok, (double)NAN, 1.0, NULL, 0.5, out, GW));
    BAD('F', INV, hfvis_viewshed_reference(&g_ok, 1.0, 1.0, NULL, (double)NAN, out, GW));
    BAD('F', INV, hfvis_viewshed_reference(&g_ok, 1.0, 1.0, NULL, (double)INFINITY, out, GW));
    BAD('G', INV, hfvis_viewshed_reference(&g_ok, 1.0, 1.0, NULL, -0.5, out, GW));
    BAD('R', INV, hfvis_viewshed_reference(&g_ok, GW, 1.0, NULL, 0.5, out, GW));
    BAD('R', INV, hfvis_viewshed_reference(&g_ok, 1.0, 1.0, NULL, 0.5, out, GW - 1));
    BAD('O', INV, hfvis_viewshed_reference(&g_ok, 1.0, 1.0, NULL, 0.5, out, PTRDIFF_MAX));
    GRID_CASES(hfvis_viewshed_reference(&bg, 1.0, 1.0, NULL, 0.5, out, GW));
    VIEWSHED_OPT_CASES(hfvis_viewshed_reference(&g_ok, 1.0, 1.0, &bv, 0.5, out, GW));
}

/* ---- Nowrouzezahrai-Snyder math layer and pipeline --------------------------------------- */

static const double v3_ok[3] = {0.3, -0.2, 0.9}, v3_zero[3] = {0, 0, 0}, v3_nan[3] = {0, (double)NAN, 1};
static const double v3_inf[3] = {(double)INFINITY, 0, 1};
static double sh16_ok[16] = {1, 0.5, 0.25, -0.5, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1, 1.1, 1.2};
static const double ahat_ok[4] = {3.14, 2.09, 0.78, 0}, ahat_nan[4] = {3.14, (double)NAN, 0.78, 0};
static double gamma_tab[4096];

static void args_sh_eval(void)
{
    double *y;
    begin("sh_eval");
    y = AD(16);
    OK(hfvis_sh_eval(v3_ok, y));
    BAD('N', INV, hfvis_sh_eval(NULL, y));
    BAD('N', INV, hfvis_sh_eval(v3_ok, NULL));
    BAD('Z', INV, hfvis_sh_eval(v3_zero, y));
    BAD('F', INV, hfvis_sh_eval(v3_nan, y));
    BAD('F', INV, hfvis_sh_eval(v3_inf, y));
}

static void args_sh_rotate_z(void)
{
    double *o;
    begin("sh_rotate_z");
    o = AD(16);
    OK(hfvis_sh_rotate_z(sh16_ok, 0.3, o));
    BAD('N', INV, hfvis_sh_rotate_z(NULL, 0.3, o));
    BAD('N', INV, hfvis_sh_rotate_z(sh16_ok, 0.3, NULL));
    BAD('F', INV, hfvis_sh_rotate_z(sh16_ok, (double)NAN, o));
    BAD('F', INV, hfvis_sh_rotate_z(sh16_ok, (double)INFINITY, o));
}

static void args_sh_dot(void)
{
    double *o;
    begin("sh_dot");
    o = AD(1);
    OK(hfvis_sh_dot(sh16_ok, sh16_ok, o));
    BAD('N', INV, hfvis_sh_dot(NULL, sh16_ok, o));
    BAD('N', INV, hfvis_sh_dot(sh16_ok, NULL, o));
    BAD('N', INV, hfvis_sh_dot(sh16_ok, sh16_ok, NULL));
}

static void args_sh_product_tensor(void)
{
    begin("sh_product_tensor");
    OK(hfvis_sh_product_tensor(gamma_tab));
    BAD('N', INV, hfvis_sh_product_tensor(NULL));
}

static void args_sh_product(void)
{
    double *o;
    begin("sh_product");
    o = AD(16);
    OK(hfvis_sh_product(gamma_tab, sh16_ok, sh16_ok, o));
    BAD('N', INV, hfvis_sh_product(NULL, sh16_ok, sh16_ok, o));
    BAD('N', INV, hfvis_sh_product(gamma_tab, NULL, sh16_ok, o));
    BAD('N', INV, hfvis_sh_product(gamma_tab, sh16_ok, NULL, o));
    BAD('N', INV, hfvis_sh_product(gamma_tab, sh16_ok, sh16_ok, NULL));
}

static void args_sh_convolve_zh(void)
{
    double *o;
    begin("sh_convolve_zh");
    o = AD(16);
    OK(hfvis_sh_convolve_zh(sh16_ok, ahat_ok, o));
    BAD('N', INV, hfvis_sh_convolve_zh(NULL, ahat_ok, o));
    BAD('N', INV, hfvis_sh_convolve_zh(sh16_ok, NULL, o));
    BAD('N', INV, hfvis_sh_convolve_zh(sh16_ok, ahat_ok, NULL));
    BAD('F', INV, hfvis_sh_convolve_zh(sh16_ok, ahat_nan, o));
}

static void args_sh_from_zh(void)
{
    double *o;
    begin("sh_from_zh");
    o = AD(16);
    OK(hfvis_sh_from_zh(ahat_ok, v3_ok, o));
    BAD('N', INV, hfvis_sh_from_zh(NULL, v3_ok, o));
    BAD('N', INV, hfvis_sh_from_zh(ahat_ok, NULL, o));
    BAD('N', INV, hfvis_sh_from_zh(ahat_ok, v3_ok, NULL));
    BAD('F', INV, hfvis_sh_from_zh(ahat_nan, v3_ok, o));
    BAD('F', INV, hfvis_sh_from_zh(ahat_ok, v3_inf, o));
    BAD('Z', INV, hfvis_sh_from_zh(ahat_ok, v3_zero, o));
}

static void args_sh_shade_zh(void)
{
    double *o;
    begin("sh_shade_zh");
    o = AD(1);
    OK(hfvis_sh_shade_zh(ahat_ok, v3_ok, sh16_ok, o));
    BAD('N', INV, hfvis_sh_shade_zh(NULL, v3_ok, sh16_ok, o));
    BAD('N', INV, hfvis_sh_shade_zh(ahat_ok, NULL, sh16_ok, o));
    BAD('N', INV, hfvis_sh_shade_zh(ahat_ok, v3_ok, NULL, o));
    BAD('N', INV, hfvis_sh_shade_zh(ahat_ok, v3_ok, sh16_ok, NULL));
    BAD('F', INV, hfvis_sh_shade_zh(ahat_nan, v3_ok, sh16_ok, o));
    BAD('F', INV, hfvis_sh_shade_zh(ahat_ok, v3_nan, sh16_ok, o));
    BAD('Z', INV, hfvis_sh_shade_zh(ahat_ok, v3_zero, sh16_ok, o));
}

static void args_zh_diffuse(void)
{
    double *a;
    begin("zh_diffuse");
    a = AD(4);
    OK(hfvis_zh_diffuse(a));
    BAD('N', INV, hfvis_zh_diffuse(NULL));
}

static void args_zh_phong(void)
{
    double *a;
    begin("zh_phong");
    a = AD(4);
    OK(hfvis_zh_phong(8.0, a));
    BAD('N', INV, hfvis_zh_phong(8.0, NULL));
    BAD('Z', INV, hfvis_zh_phong(0.0, a));
    BAD('G', INV, hfvis_zh_phong(-1.0, a));
    BAD('F', INV, hfvis_zh_phong((double)NAN, a));
    BAD('F', INV, hfvis_zh_phong((double)INFINITY, a));
}

static void args_zh_cap(void)
{
    double *a;
    begin("zh_cap");
    a = AD(4);
    OK(hfvis_zh_cap(0.5, a));
    BAD('N', INV, hfvis_zh_cap(0.5, NULL));
    BAD('G', INV, hfvis_zh_cap(-0.1, a));
    BAD('R', INV, hfvis_zh_cap(4.0, a));
    BAD('F', INV, hfvis_zh_cap((double)NAN, a));
}

static void args_sh_project_env(void)
{
    double *o;
    begin("sh_project_env");
    o = AD(16);
    OK(hfvis_sh_project_env(&g_env, o));
    BAD('N', INV, hfvis_sh_project_env(NULL, o));
    BAD('N', INV, hfvis_sh_project_env(&g_env, NULL));
    ENV_CASES(hfvis_sh_project_env(&be, o));
}

static void args_nlp_eval(void)
{
    double *p;
    begin("nlp_eval");
    p = AD(4);
    OK(hfvis_nlp_eval(0.5, p));
    BAD('N', INV, hfvis_nlp_eval(0.5, NULL));
    BAD('F', INV, hfvis_nlp_eval((double)NAN, p));
    BAD('R', INV, hfvis_nlp_eval(1.5, p));
    BAD('G', INV, hfvis_nlp_eval(-1.5, p));
}

static void args_nlp_occlusion(void)
{
    double *p;
    begin("nlp_occlusion");
    p = AD(4);
    OK(hfvis_nlp_occlusion(0.5, p));
    BAD('N', INV, hfvis_nlp_occlusion(0.5, NULL));
    BAD('F', INV, hfvis_nlp_occlusion((double)NAN, p));
    BAD('F', INV, hfvis_nlp_occlusion(-(double)INFINITY, p));
}

static void args_nlp_visibility(void)
{
    double *p;
    begin("nlp_visibility");
    p = AD(4);
    OK(hfvis_nlp_visibility(0.1, 0.5, p));
    BAD('N', INV, hfvis_nlp_visibility(0.1, 0.5, NULL));
    BAD('F', INV, hfvis_nlp_visibility((double)NAN, 0.5, p));
    BAD('F', INV, hfvis_nlp_visibility(0.1, (double)INFINITY, p));
}

static void args_nlp_radiance(void)
{
    static const double om[2] = {0.1, 0.3}, u[2] = {1, 2}, ombad[2] = {0.3, 0.1}, omnan[2] = {0.1, (double)NAN};
    double *p;
    begin("nlp_radiance");
    p = AD(4);
    OK(hfvis_nlp_radiance(2, om, u, 0.0, p));
    OK(hfvis_nlp_radiance(0, NULL, NULL, 0.0, p));
    BAD('N', INV, hfvis_nlp_radiance(2, NULL, u, 0.0, p));
    BAD('N', INV, hfvis_nlp_radiance(2, om, NULL, 0.0, p));
    BAD('N', INV, hfvis_nlp_radiance(2, om, u, 0.0, NULL));
    BAD('G', INV, hfvis_nlp_radiance(-1, om, u, 0.0, p));
    BAD('R', INV, hfvis_nlp_radiance(2, ombad, u, 0.0, p));
    BAD('R', INV, hfvis_nlp_radiance(2, om, u, 0.2, p));
    BAD('F', INV, hfvis_nlp_radiance(2, omnan, u, 0.0, p));
    BAD('F', INV, hfvis_nlp_radiance(2, om, u, (double)NAN, p));
}

static void args_nlp_reconstruct(void)
{
    static const double c[4] = {1, 0.5, 0.2, 0.1};
    double *o;
    begin("nlp_reconstruct");
    o = AD(1);
    OK(hfvis_nlp_reconstruct(c, 0.3, o));
    BAD('N', INV, hfvis_nlp_reconstruct(NULL, 0.3, o));
    BAD('N', INV, hfvis_nlp_reconstruct(c, 0.3, NULL));
    BAD('F', INV, hfvis_nlp_reconstruct(c, (double)NAN, o));
}

static void args_ns_wedge_columns(void)
{
    begin("ns_wedge_columns");
    CHECK(hfvis_ns_wedge_columns(HFVIS_NS_INTERP_LINEAR) == 8);
    BADV('E', hfvis_ns_wedge_columns((hfvis_ns_interp)99) == 0);
    BADV('E', hfvis_ns_wedge_columns((hfvis_ns_interp)-1) == 0);
}

static void args_ns_wedge_matrix(void)
{
    double *M;
    begin("ns_wedge_matrix");
    M = AD(HFVIS_NS_WEDGE_MATRIX_MAX);
    OK(hfvis_ns_wedge_matrix(HFVIS_NS_INTERP_LINEAR, 0.5, M));
    BAD('N', INV, hfvis_ns_wedge_matrix(HFVIS_NS_INTERP_LINEAR, 0.5, NULL));
    BAD('E', INV, hfvis_ns_wedge_matrix((hfvis_ns_interp)99, 0.5, M));
    BAD('Z', INV, hfvis_ns_wedge_matrix(HFVIS_NS_INTERP_LINEAR, 0.0, M));
    BAD('G', INV, hfvis_ns_wedge_matrix(HFVIS_NS_INTERP_LINEAR, -0.5, M));
    BAD('R', INV, hfvis_ns_wedge_matrix(HFVIS_NS_INTERP_LINEAR, 7.0, M));
    BAD('F', INV, hfvis_ns_wedge_matrix(HFVIS_NS_INTERP_LINEAR, (double)NAN, M));
}

static void args_ns_wedges_full(void)
{
    hfvis_ns_wedges *w;
    begin("ns_wedges_full");
    w = AT(hfvis_ns_wedges);
    OK(hfvis_ns_wedges_full(w, HFVIS_NS_INTERP_LINEAR, 4, 0.0));
    BAD('N', INV, hfvis_ns_wedges_full(NULL, HFVIS_NS_INTERP_LINEAR, 4, 0.0));
    BAD('E', INV, hfvis_ns_wedges_full(w, (hfvis_ns_interp)99, 4, 0.0));
    BAD('Z', INV, hfvis_ns_wedges_full(w, HFVIS_NS_INTERP_LINEAR, 0, 0.0));
    BAD('G', INV, hfvis_ns_wedges_full(w, HFVIS_NS_INTERP_LINEAR, -4, 0.0));
    BAD('F', INV, hfvis_ns_wedges_full(w, HFVIS_NS_INTERP_LINEAR, 4, (double)NAN));
}

static void args_ns_wedges_partial(void)
{
    hfvis_ns_wedges *w;
    begin("ns_wedges_partial");
    w = AT(hfvis_ns_wedges);
    OK(hfvis_ns_wedges_partial(w, HFVIS_NS_INTERP_LINEAR, 3, -0.3, 0.2));
    BAD('N', INV, hfvis_ns_wedges_partial(NULL, HFVIS_NS_INTERP_LINEAR, 3, -0.3, 0.2));
    BAD('E', INV, hfvis_ns_wedges_partial(w, (hfvis_ns_interp)99, 3, -0.3, 0.2));
    BAD('R', INV, hfvis_ns_wedges_partial(w, HFVIS_NS_INTERP_LINEAR, 1, -0.3, 0.2));
    BAD('G', INV, hfvis_ns_wedges_partial(w, HFVIS_NS_INTERP_LINEAR, -3, -0.3, 0.2));
    BAD('R', INV, hfvis_ns_wedges_partial(w, HFVIS_NS_INTERP_LINEAR, 3, 0.2, -0.3));
    BAD('R', INV, hfvis_ns_wedges_partial(w, HFVIS_NS_INTERP_LINEAR, 3, 0.0, 7.0));
    BAD('F', INV, hfvis_ns_wedges_partial(w, HFVIS_NS_INTERP_LINEAR, 3, (double)NAN, 0.2));
}

static hfvis_ns_wedges wedges_ok(void)
{
    hfvis_ns_wedges w;
    hfvis_ns_wedges_full(&w, HFVIS_NS_INTERP_LINEAR, 4, 0.0);
    return w;
}

static void args_ns_wedges_to_sh(void)
{
    static double wv[16];
    hfvis_ns_wedges w = wedges_ok(), b;
    double *o;
    begin("ns_wedges_to_sh");
    o = AD(16);
    OK(hfvis_ns_wedges_to_sh(&w, wv, o));
    BAD('N', INV, hfvis_ns_wedges_to_sh(NULL, wv, o));
    BAD('N', INV, hfvis_ns_wedges_to_sh(&w, NULL, o));
    BAD('N', INV, hfvis_ns_wedges_to_sh(&w, wv, NULL));
    b = w; b.interp = (hfvis_ns_interp)99; BAD('E', INV, hfvis_ns_wedges_to_sh(&b, wv, o));
    b = w; b.samples = 0; BAD('Z', INV, hfvis_ns_wedges_to_sh(&b, wv, o));
    b = w; b.samples = -1; BAD('G', INV, hfvis_ns_wedges_to_sh(&b, wv, o));
}

static void args_ns_min_blocking_angle(void)
{
    double *o;
    begin("ns_min_blocking_angle");
    o = AD(1);
    OK(hfvis_ns_min_blocking_angle(v3_ok, 0.3, HFVIS_NS_OMEGA_MIN_EXACT, o));
    BAD('N', INV, hfvis_ns_min_blocking_angle(NULL, 0.3, HFVIS_NS_OMEGA_MIN_EXACT, o));
    BAD('N', INV, hfvis_ns_min_blocking_angle(v3_ok, 0.3, HFVIS_NS_OMEGA_MIN_EXACT, NULL));
    BAD('Z', INV, hfvis_ns_min_blocking_angle(v3_zero, 0.3, HFVIS_NS_OMEGA_MIN_EXACT, o));
    BAD('F', INV, hfvis_ns_min_blocking_angle(v3_nan, 0.3, HFVIS_NS_OMEGA_MIN_EXACT, o));
    BAD('F', INV, hfvis_ns_min_blocking_angle(v3_ok, (double)INFINITY, HFVIS_NS_OMEGA_MIN_EXACT, o));
    BAD('E', INV, hfvis_ns_min_blocking_angle(v3_ok, 0.3, (hfvis_ns_omega_min)99, o));
}

static void args_ns_gi_options_default(void)
{
    hfvis_ns_gi_options o = hfvis_ns_gi_options_default();
    begin("ns_gi_options_default");
    CHECK(o.levels == 0);
}

#define NSGI_OPT_CASES(expr) do { hfvis_ns_gi_options bn; \
    bn = hfvis_ns_gi_options_default(); bn.directions = -1; BAD('S', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.directions = HFVIS_NS_MAX_DIRECTIONS + 1; BAD('O', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.levels = HFVIS_NS_MAX_LEVELS + 1; BAD('O', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.sh_order = 5; BAD('S', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.interp = (hfvis_ns_interp)99; BAD('E', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.glossy = (hfvis_ns_glossy)-1; BAD('E', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.border = (hfvis_border)7; BAD('E', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.view_dir[0] = (double)NAN; BAD('F', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.azimuth0_rad = (double)INFINITY; BAD('F', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.key_directions = 1; BAD('S', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.levels_per_octave = 33; BAD('O', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.level_offset_v = -2; BAD('G', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.subsample = 65; BAD('O', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.omega_min = (hfvis_ns_omega_min)9; BAD('E', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.omega_max = (hfvis_ns_omega_max)9; BAD('E', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.directional = (hfvis_ns_directional)9; BAD('E', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.key_mode = (hfvis_ns_key_mode)9; BAD('E', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.cast_cache = (hfvis_ns_cache)9; BAD('E', INV, expr); \
    bn = hfvis_ns_gi_options_default(); bn.clamp_to_tangent = 2; BAD('S', INV, expr); \
    } while (0)

static void args_ns_gi_options_resolve(void)
{
    hfvis_ns_gi_options *o;
    begin("ns_gi_options_resolve");
    o = AT(hfvis_ns_gi_options);
    OK(hfvis_ns_gi_options_resolve(&g_ok, NULL, o));
    BAD('N', INV, hfvis_ns_gi_options_resolve(NULL, NULL, o));
    BAD('N', INV, hfvis_ns_gi_options_resolve(&g_ok, NULL, NULL));
    GRID_CASES(hfvis_ns_gi_options_resolve(&bg, NULL, o));
    NSGI_OPT_CASES(hfvis_ns_gi_options_resolve(&g_ok, &bn, o));
}

static double ns_env_sh[16] = {3.5449077018110318};

static hfvis_ns_scene ns_scene_ok(void)
{
    hfvis_ns_scene s;
    memset(&s, 0, sizeof s);
    s.channels = 1; s.env_sh = ns_env_sh; s.albedo[0] = 0.5f;
    return s;
}

#define NS_SCENE_CASES(expr) do { hfvis_ns_scene bs; static hfvis_sun bsun; \
    bs = ns_scene_ok(); bs.channels = 0; BAD('Z', INV, expr); \
    bs = ns_scene_ok(); bs.channels = 5; BAD('S', INV, expr); \
    bs = ns_scene_ok(); bs.light_count = -1; BAD('G', INV, expr); \
    bs = ns_scene_ok(); bs.light_count = 65; bs.lights = &bsun; BAD('O', INV, expr); \
    bs = ns_scene_ok(); bs.light_count = 1; bs.lights = NULL; BAD('N', INV, expr); \
    bs = ns_scene_ok(); memset(&bsun, 0, sizeof bsun); bsun.elevation_rad = (double)NAN; bs.light_count = 1; \
    bs.lights = &bsun; BAD('F', INV, expr); \
    bs = ns_scene_ok(); bs.albedo[0] = (double)NAN; BAD('F', INV, expr); \
    bs = ns_scene_ok(); bs.specular = -1.0f; BAD('S', INV, expr); \
    bs = ns_scene_ok(); bs.specular = 1.0f; bs.shininess = 0.0f; BAD('S', INV, expr); \
    bs = ns_scene_ok(); bs.albedo_map = ns_bad_map; BAD('F', INV, expr); \
    bs = ns_scene_ok(); bs.emission = ns_bad_map; BAD('F', INV, expr); \
    bs = ns_scene_ok(); bs.env_sh = ns_bad_sh; BAD('F', INV, expr); \
    } while (0)
/* A per-sample map with one NaN at sample 5 (not a hole), and an SH vector with an Inf. */
static const float ns_bad_map[GW * GH] = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, (double)NAN, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f};
static const double ns_bad_sh[16] = {1.0, (double)INFINITY};

static void args_ns_gi(void)
{
    hfvis_ns_scene sc = ns_scene_ok();
    hfvis_ns_gi_options o = hfvis_ns_gi_options_default();
    hfvis_ns_gi_outputs out, b;
    begin("ns_gi");
    o.directions = 4;
    memset(&out, 0, sizeof out);
    out.bounces = 1;
    out.total = AF(GW * GH);
    out.direct = AF(GW * GH);
    out.bounce = AF(GW * GH);
    OK(hfvis_ns_gi(&g_ok, &sc, &o, &out));
    BAD('N', INV, hfvis_ns_gi(NULL, &sc, &o, &out));
    BAD('N', INV, hfvis_ns_gi(&g_ok, NULL, &o, &out));
    BAD('N', INV, hfvis_ns_gi(&g_ok, &sc, &o, NULL));
    b = out; b.bounces = -1; BAD('G', INV, hfvis_ns_gi(&g_ok, &sc, &o, &b));
    GRID_CASES(hfvis_ns_gi(&bg, &sc, &o, &out));
    NSGI_OPT_CASES(hfvis_ns_gi(&g_ok, &sc, &bn, &out));
    NS_SCENE_CASES(hfvis_ns_gi(&g_ok, &bs, &o, &out));
}

static void args_ns_gi_scratch_size(void)
{
    hfvis_ns_scene sc = ns_scene_ok();
    size_t *bytes;
    begin("ns_gi_scratch_size");
    bytes = AT(size_t);
    OK(hfvis_ns_gi_scratch_size(&g_ok, &sc, NULL, 1, bytes));
    BAD('N', INV, hfvis_ns_gi_scratch_size(NULL, &sc, NULL, 1, bytes));
    BAD('N', INV, hfvis_ns_gi_scratch_size(&g_ok, NULL, NULL, 1, bytes));
    BAD('N', INV, hfvis_ns_gi_scratch_size(&g_ok, &sc, NULL, 1, NULL));
    BAD('G', INV, hfvis_ns_gi_scratch_size(&g_ok, &sc, NULL, -1, bytes));
    GRID_CASES(hfvis_ns_gi_scratch_size(&bg, &sc, NULL, 1, bytes));
    NSGI_OPT_CASES(hfvis_ns_gi_scratch_size(&g_ok, &sc, &bn, 1, bytes));
    NS_SCENE_CASES(hfvis_ns_gi_scratch_size(&g_ok, &bs, NULL, 1, bytes));
}

static void args_ns_bspline_max(void)
{
    static const double om[3] = {0.1, 0.5, 0.2}, omnan[3] = {0.1, (double)NAN, 0.2};
    double *o;
    begin("ns_bspline_max");
    o = AD(1);
    OK(hfvis_ns_bspline_max(3, om, o));
    OK(hfvis_ns_bspline_max(0, NULL, o));
    BAD('N', INV, hfvis_ns_bspline_max(3, NULL, o));
    BAD('N', INV, hfvis_ns_bspline_max(3, om, NULL));
    BAD('G', INV, hfvis_ns_bspline_max(-1, om, o));
    BAD('F', INV, hfvis_ns_bspline_max(3, omnan, o));
}

static void args_ns_sample_matrices(void)
{
    hfvis_ns_wedges w = wedges_ok(), b;
    double *G;
    begin("ns_sample_matrices");
    G = AD(64 * 4);
    OK(hfvis_ns_sample_matrices(&w, G));
    BAD('N', INV, hfvis_ns_sample_matrices(NULL, G));
    BAD('N', INV, hfvis_ns_sample_matrices(&w, NULL));
    b = w; b.interp = (hfvis_ns_interp)99; BAD('E', INV, hfvis_ns_sample_matrices(&b, G));
    b = w; b.samples = 0; BAD('Z', INV, hfvis_ns_sample_matrices(&b, G));
}

/* ---- split runs: raw direction sums and the partial-sum file ------------------------------ */

static void args_direction_sums(void)
{
    hfvis_sweep_options o;
    double *sums;
    begin("direction_sums");
    sums = AD(GW * GH);
    OK(hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_SKY_VIEW, NULL, NULL, NULL, sums));
    OK(hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_SKY_LIGHT, NULL, NULL, NULL, sums));
    OK(hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_ENV_LIGHT, &g_env, NULL, NULL, sums));
    OK(hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_VISIBILITY, NULL, NULL, NULL, sums));
    o = hfvis_sweep_options_default();
    o.direction_begin = 1; o.direction_end = 3; o.direction_order = HFVIS_DIRECTION_ORDER_SWEEP;
    OK(hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, sums));
    BAD('N', INV, hfvis_direction_sums(NULL, 4, HFVIS_SUM_SKY_VIEW, NULL, NULL, NULL, sums));
    BAD('N', INV, hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_SKY_VIEW, NULL, NULL, NULL, NULL));
    BAD('N', INV, hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_ENV_LIGHT, NULL, NULL, NULL, sums));
    BAD('Z', INV, hfvis_direction_sums(&g_ok, 0, HFVIS_SUM_SKY_VIEW, NULL, NULL, NULL, sums));
    BAD('G', INV, hfvis_direction_sums(&g_ok, -4, HFVIS_SUM_VISIBILITY, NULL, NULL, NULL, sums));
    BAD('E', INV, hfvis_direction_sums(&g_ok, 4, (hfvis_sum_kind)0, NULL, NULL, NULL, sums));
    BAD('E', INV, hfvis_direction_sums(&g_ok, 4, (hfvis_sum_kind)5, NULL, NULL, NULL, sums));
    BAD('E', INV, hfvis_direction_sums(&g_ok, 4, (hfvis_sum_kind)-1, NULL, NULL, NULL, sums));
    o = hfvis_sweep_options_default(); o.direction_end = 5;
    BAD('S', INV, hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, sums));
    o = hfvis_sweep_options_default(); o.direction_begin = 2; o.direction_end = 2;
    BAD('S', INV, hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_SKY_LIGHT, NULL, NULL, &o, sums));
    o = hfvis_sweep_options_default(); o.direction_begin = 3; o.direction_end = 1;
    BAD('S', INV, hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_VISIBILITY, NULL, NULL, &o, sums));
    o = hfvis_sweep_options_default(); o.direction_order = (hfvis_direction_order)3;
    BAD('E', INV, hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, sums));
    o = hfvis_sweep_options_default(); o.direction_order = (hfvis_direction_order)-1;
    BAD('E', INV, hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_ENV_LIGHT, &g_env, NULL, &o, sums));
    o = hfvis_sweep_options_default(); o.part_index = 1; o.part_count = 3; /* bands: exact rays only */
    BAD('S', INV, hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, sums));
    o.rays = HFVIS_RAYS_EXACT;
    OK(hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, sums));
    OK(hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_SKY_LIGHT, NULL, NULL, &o, sums));
    OK(hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_ENV_LIGHT, &g_env, NULL, &o, sums));
    BAD('S', INV, hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_VISIBILITY, NULL, NULL, &o, sums));
    o.part_index = 3;
    BAD('S', INV, hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, sums));
    GRID_CASES(hfvis_direction_sums(&bg, 4, HFVIS_SUM_SKY_VIEW, NULL, NULL, NULL, sums));
    GRID_CASES(hfvis_direction_sums(&bg, 4, HFVIS_SUM_VISIBILITY, NULL, NULL, NULL, sums));
    SWEEP_OPT_CASES(hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_SKY_LIGHT, NULL, NULL, &bo, sums));
    SWEEP_OPT_CASES(hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_ENV_LIGHT, &g_env, NULL, &bo, sums));
    P2_RADIUS_CASES(hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_VISIBILITY, NULL, NULL, &bo, sums));
    ENV_CASES(hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_ENV_LIGHT, &be, NULL, NULL, sums));
    EOPT_CASES(hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_ENV_LIGHT, &g_env, &bx, NULL, sums));
}

/* A valid partial: the 4 x 3 grid, one plane, directions [1, 3) of 4. */
static double p_sums[GW * GH] = {0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5, 5.0, 5.5};
static const hfvis_partial p_ok = {GW, GH, 1, 4, 1, 3, "svf K=4", p_sums};
static unsigned char p_file[512];
static size_t p_file_len;

/* A tag one byte over HFVIS_PARTIAL_MAX_TAG. */
static const char *long_tag(void)
{
    static char t[HFVIS_PARTIAL_MAX_TAG + 2];
    memset(t, 'a', HFVIS_PARTIAL_MAX_TAG + 1);
    t[HFVIS_PARTIAL_MAX_TAG + 1] = '\0';
    return t;
}

/* Invalid partials, substituted as &bp; CASE(cls, expr) is P_INV (status) or P_ZERO (size). */
#define P_INV(cls, expr) BAD(cls, INV, expr)
#define P_ZERO(cls, expr) BADV(cls, (expr) == 0)
#define PARTIAL_CASES(CASE, expr) do { hfvis_partial bp; \
    bp = p_ok; bp.sums = NULL; CASE('N', expr); \
    bp = p_ok; bp.tag = NULL; CASE('N', expr); \
    bp = p_ok; bp.width = 0; CASE('Z', expr); \
    bp = p_ok; bp.planes = 0; CASE('Z', expr); \
    bp = p_ok; bp.directions = 0; CASE('Z', expr); \
    bp = p_ok; bp.tag = ""; CASE('Z', expr); \
    bp = p_ok; bp.height = -1; CASE('G', expr); \
    bp = p_ok; bp.begin = -1; CASE('G', expr); \
    bp = p_ok; bp.width = HFVIS_IMAGE_MAX_DIM + 1; CASE('O', expr); \
    bp = p_ok; bp.planes = HFVIS_PARTIAL_MAX_PLANES + 1; CASE('O', expr); \
    bp = p_ok; bp.width = 65536; bp.height = 65536; bp.planes = 2; CASE('O', expr); \
    bp = p_ok; bp.tag = long_tag(); CASE('O', expr); \
    bp = p_ok; bp.tag = "svf\nK=4"; CASE('R', expr); \
    bp = p_ok; bp.tag = "svf\x7f"; CASE('R', expr); \
    bp = p_ok; bp.end = bp.begin; CASE('S', expr); \
    bp = p_ok; bp.end = 5; CASE('S', expr); \
    bp = p_ok; bp.begin = 3; bp.end = 1; CASE('S', expr); \
    } while (0)

static void args_partial_encode_size(void)
{
    begin("partial_encode_size");
    CHECK(hfvis_partial_encode_size(&p_ok) == 11 + 12 + 8 + 8 * GW * GH + 4);
    BADV('N', hfvis_partial_encode_size(NULL) == 0);
    PARTIAL_CASES(P_ZERO, hfvis_partial_encode_size(&bp));
}

static void args_partial_encode(void)
{
    size_t need = hfvis_partial_encode_size(&p_ok), *wr;
    unsigned char *out;
    begin("partial_encode");
    out = ATN(unsigned char, need); wr = AT(size_t);
    OK(hfvis_partial_encode(&p_ok, out, need, wr));
    BAD('N', INV, hfvis_partial_encode(NULL, out, need, wr));
    BAD('N', INV, hfvis_partial_encode(&p_ok, NULL, need, wr));
    BAD('N', INV, hfvis_partial_encode(&p_ok, out, need, NULL));
    BAD('Z', SMALL, hfvis_partial_encode(&p_ok, out, 0, wr));
    BAD('R', SMALL, hfvis_partial_encode(&p_ok, out, need - 1, wr));
    PARTIAL_CASES(P_INV, hfvis_partial_encode(&bp, out, need, wr));
}

/* A file of header text head followed by values zero doubles and the CRC-32 trailer of the
 * HFVISSUM format, into buf (cap bytes). */
static size_t partial_file(unsigned char *buf, size_t cap, const char *head, size_t values)
{
    size_t n = strlen(head), k;
    uint32_t crc;
    if (n + 8 * values + 4 > cap) exit(2);
    memcpy(buf, head, n);
    memset(buf + n, 0, 8 * values);
    crc = hfvis_crc32(0, buf, n + 8 * values);
    for (k = 0; k < 4; k++) buf[n + 8 * values + k] = (unsigned char)(crc >> (8 * k));
    return n + 8 * values + 4;
}

static unsigned char p_bad[HFVIS_PARTIAL_MAX_TAG + 256];

static void args_partial_decode(void)
{
    /* a header with the numbers line nums; a 4 x 3 one-plane file has 12 values */
#define P_HEAD(nums) "HFVISSUM 2\n" nums "\nsvf K=4\n"
    hfvis_partial *p;
    size_t n;
    char head[HFVIS_PARTIAL_MAX_TAG + 64];
    begin("partial_decode");
    CHECK(hfvis_partial_encode(&p_ok, p_file, sizeof p_file, &p_file_len) == HFVIS_OK);
    p = AT(hfvis_partial);
    arena_fill();
    base_status(hfvis_partial_decode(p_file, p_file_len, NULL, p), __LINE__);
    hfvis_partial_free(NULL, p);
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("4 3 1 4 0 4"), 12);
    OK(hfvis_partial_decode(p_bad, n, NULL, p));
    hfvis_partial_free(NULL, p);
    BAD('N', INV, hfvis_partial_decode(NULL, p_file_len, NULL, p));
    BAD('N', INV, hfvis_partial_decode(p_file, p_file_len, NULL, NULL));
    BAD('Z', FMT, hfvis_partial_decode(p_file, 0, NULL, p));
    BAD('R', FMT, hfvis_partial_decode(p_file, p_file_len - 1, NULL, p));
    BAD('R', FMT, hfvis_partial_decode(p_file, 20, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("4 3 1 4 0 4"), 13);
    BAD('R', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("0 3 1 4 0 4"), 0);
    BAD('Z', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("4 3 0 4 0 4"), 0);
    BAD('Z', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("4 3 1 0 0 4"), 12);
    BAD('Z', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, "HFVISSUM 2\n4 3 1 4 0 4\n\n", 12);
    BAD('Z', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("4 -3 1 4 0 4"), 12);
    BAD('G', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("4 3 1 4 -1 4"), 12);
    BAD('G', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("1048577 1 1 4 0 4"), 0);
    BAD('O', LIM, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("4 3 65537 4 0 4"), 0);
    BAD('O', LIM, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("65536 65536 2 4 0 4"), 0);
    BAD('O', LIM, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("2147483648 3 1 4 0 4"), 0);
    BAD('O', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    snprintf(head, sizeof head, "HFVISSUM 2\n4 3 1 4 0 4\n%s\n", long_tag());
    n = partial_file(p_bad, sizeof p_bad, head, 12);
    BAD('O', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("inf 3 1 4 0 4"), 12);
    BAD('F', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("nan 3 1 4 0 4"), 12);
    BAD('F', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, "HFVISSUM 1\n4 3 1 4 0 4\nsvf K=4\n", 12);
    BAD('E', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, "HFVISSUN 1\n4 3 1 4 0 4\nsvf K=4\n", 12);
    BAD('E', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("4 3 1 4 2 2"), 12);
    BAD('R', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("4 3 1 4 0 5"), 12);
    BAD('R', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("04 3 1 4 0 4"), 12);
    BAD('R', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("4  3 1 4 0 4"), 12);
    BAD('R', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, P_HEAD("4 3 1 4 0 4 5"), 12);
    BAD('R', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, "HFVISSUM 2\n4 3 1 4 0 4\nsvf\tK=4\n", 12);
    BAD('R', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
    n = partial_file(p_bad, sizeof p_bad, "HFVISSUM 2\n4 3 1 4 0 4\nsvf K=4", 0);
    BAD('R', FMT, hfvis_partial_decode(p_bad, n, NULL, p));
#undef P_HEAD
}

static void args_partial_free(void)
{
    hfvis_partial p;
    begin("partial_free");
    memset(&p, 0, sizeof p);
    hfvis_partial_free(NULL, NULL);
    hfvis_partial_free(NULL, &p);
    BADV('N', p.sums == NULL && p.tag == NULL);
}

static void args_partial_save(void)
{
    begin("partial_save");
    OK(hfvis_partial_save(tmp_path("s.hfvs"), &p_ok));
    BAD('N', INV, hfvis_partial_save(NULL, &p_ok));
    BAD('N', INV, hfvis_partial_save(tmp_path("t.hfvs"), NULL));
    BAD('R', IOE, hfvis_partial_save(bad_dir_path("t.hfvs"), &p_ok));
    PARTIAL_CASES(P_INV, hfvis_partial_save(tmp_path("t.hfvs"), &bp));
    BADV('R', access(tmp_path("t.hfvs"), F_OK) != 0);
}

/* Writes n bytes to the temporary file leaf. */
static void write_tmp(const char *leaf, const void *data, size_t n)
{
    FILE *f = fopen(tmp_path(leaf), "wb");
    CHECK(f != NULL);
    if (!f) return;
    CHECK(fwrite(data, 1, n, f) == n);
    fclose(f);
}

static void args_partial_load(void)
{
    hfvis_partial *p;
    size_t n;
    begin("partial_load");
    write_tmp("empty.hfvs", "", 0);
    write_tmp("short.hfvs", p_file, p_file_len - 1);
    n = partial_file(p_bad, sizeof p_bad, "HFVISSUM 2\n1048576 1048576 1 4 0 4\nsvf K=4\n", 0);
    write_tmp("huge.hfvs", p_bad, n);
    p = AT(hfvis_partial);
    arena_fill();
    base_status(hfvis_partial_load(tmp_path("s.hfvs"), NULL, p), __LINE__);
    CHECK(p->width == GW && p->begin == 1 && p->end == 3 && strcmp(p->tag, p_ok.tag) == 0 &&
          memcmp(p->sums, p_sums, sizeof p_sums) == 0);
    hfvis_partial_free(NULL, p);
    BAD('N', INV, hfvis_partial_load(NULL, NULL, p));
    BAD('N', INV, hfvis_partial_load(tmp_path("s.hfvs"), NULL, NULL));
    BAD('R', IOE, hfvis_partial_load(tmp_path("missing.hfvs"), NULL, p));
    BAD('Z', FMT, hfvis_partial_load(tmp_path("empty.hfvs"), NULL, p));
    BAD('R', FMT, hfvis_partial_load(tmp_path("short.hfvs"), NULL, p));
    BAD('O', LIM, hfvis_partial_load(tmp_path("huge.hfvs"), NULL, p));
}

/* ========================================================================================== */
/* ssao.c: camera, depth, falloff, lattice, LSAO, HBAO, ray-traced reference, FFAO            */
/* ========================================================================================== */

#define INNER 6 /* inner width and height of cam_ok (8 - 2*guard) */

/* Invalid cameras, substituted as &bc. hfvis_camera_check reports a camera past
 * HFVIS_SSAO_MAX_SIZE as HFVIS_ERR_LIMIT; every routine that takes a camera rejects it as
 * invalid (hfvis.h: "HFVIS_ERR_INVALID_ARGUMENT for an invalid camera"). */
#define CAMERA_CASES(expr) CAMERA_CASES_LIM(expr, INV)
#define CAMERA_CASES_LIM(expr, limit_status) do { hfvis_camera bc; \
    bc = cam_ok; bc.width = 0; BAD('Z', INV, expr); \
    bc = cam_ok; bc.height = -1; BAD('G', INV, expr); \
    bc = cam_ok; bc.stride = 3; BAD('R', INV, expr); \
    bc = cam_ok; bc.guard_x = 4; BAD('R', INV, expr); \
    bc = cam_ok; bc.projection = (hfvis_camera_projection)9; BAD('E', INV, expr); \
    bc = cam_ok; bc.fx = (double)NAN; BAD('F', INV, expr); \
    bc = cam_ok; bc.fy = 0.0; BAD('Z', INV, expr); \
    bc = cam_ok; bc.cx = (double)INFINITY; BAD('F', INV, expr); \
    bc = cam_ok; bc.far_depth = -1.0; BAD('G', INV, expr); \
    bc = cam_ok; bc.rows_bottom_up = 2; BAD('R', INV, expr); \
    bc = cam_ok; bc.width = HFVIS_SSAO_MAX_SIZE + 1; BAD('O', limit_status, expr); \
    } while (0)

static void args_camera_check(void)
{
    begin("camera_check");
    OK(hfvis_camera_check(&cam_ok));
    BAD('N', INV, hfvis_camera_check(NULL));
    CAMERA_CASES_LIM(hfvis_camera_check(&bc), LIM);
}

static void args_camera_perspective(void)
{
    hfvis_camera *c;
    begin("camera_perspective");
    c = AT(hfvis_camera);
    OK(hfvis_camera_perspective(c, 8, 8, 1, 1, 1.0));
    BAD('N', INV, hfvis_camera_perspective(NULL, 8, 8, 1, 1, 1.0));
    BAD('Z', INV, hfvis_camera_perspective(c, 0, 8, 1, 1, 1.0));
    BAD('G', INV, hfvis_camera_perspective(c, 8, 8, -1, 1, 1.0));
    BAD('R', INV, hfvis_camera_perspective(c, 8, 8, 4, 1, 1.0));
    BAD('Z', INV, hfvis_camera_perspective(c, 8, 8, 1, 1, 0.0));
    BAD('R', INV, hfvis_camera_perspective(c, 8, 8, 1, 1, 3.2));
    BAD('F', INV, hfvis_camera_perspective(c, 8, 8, 1, 1, (double)NAN));
    BAD('O', LIM, hfvis_camera_perspective(c, HFVIS_SSAO_MAX_SIZE + 1, 8, 1, 1, 1.0));
}

static void args_camera_orthographic(void)
{
    hfvis_camera *c;
    begin("camera_orthographic");
    c = AT(hfvis_camera);
    OK(hfvis_camera_orthographic(c, 8, 8, 1, 1, 0.1));
    BAD('N', INV, hfvis_camera_orthographic(NULL, 8, 8, 1, 1, 0.1));
    BAD('Z', INV, hfvis_camera_orthographic(c, 8, 0, 1, 1, 0.1));
    BAD('G', INV, hfvis_camera_orthographic(c, 8, 8, 1, -1, 0.1));
    BAD('Z', INV, hfvis_camera_orthographic(c, 8, 8, 1, 1, 0.0));
    BAD('G', INV, hfvis_camera_orthographic(c, 8, 8, 1, 1, -0.1));
    BAD('F', INV, hfvis_camera_orthographic(c, 8, 8, 1, 1, (double)INFINITY));
    BAD('O', LIM, hfvis_camera_orthographic(c, 8, HFVIS_SSAO_MAX_SIZE + 1, 1, 1, 0.1));
}

static void args_camera_from_view(void)
{
    hfvis_camera *c;
    hfvis_view b;
    begin("camera_from_view");
    c = AT(hfvis_camera);
    OK(hfvis_camera_from_view(c, &view_ok, 1, 1));
    BAD('N', INV, hfvis_camera_from_view(NULL, &view_ok, 1, 1));
    BAD('N', INV, hfvis_camera_from_view(c, NULL, 1, 1));
    BAD('G', INV, hfvis_camera_from_view(c, &view_ok, -1, 1));
    BAD('R', INV, hfvis_camera_from_view(c, &view_ok, 1, 4));
    b = view_ok; b.width = 0; BAD('Z', INV, hfvis_camera_from_view(c, &b, 1, 1));
    b = view_ok; b.proj[0] = (double)NAN; BAD('F', INV, hfvis_camera_from_view(c, &b, 1, 1));
    b = view_ok; b.proj[3] = 1.0; BAD('S', INV, hfvis_camera_from_view(c, &b, 1, 1));
    b = view_ok; b.width = HFVIS_SSAO_MAX_SIZE + 1; BAD('O', LIM, hfvis_camera_from_view(c, &b, 1, 1));
}

static void args_camera_from_matrix(void)
{
    /* a GL perspective matrix (n = 0.5, f = 50), column-major */
    static const double gl[16] = {1.5, 0, 0, 0, 0, 2.0, 0, 0, 0, 0, -50.5 / 49.5, -1, 0, 0, -50.0 / 49.5, 0};
    double b[16];
    hfvis_camera *c;
    hfvis_projection_depth *d;
    begin("camera_from_matrix");
    c = AT(hfvis_camera);
    d = AT(hfvis_projection_depth);
    OK(hfvis_camera_from_matrix(c, gl, HFVIS_CLIP_DEPTH_GL, 8, 8, 1, 1, d));
    BAD('N', INV, hfvis_camera_from_matrix(NULL, gl, HFVIS_CLIP_DEPTH_GL, 8, 8, 1, 1, d));
    BAD('N', INV, hfvis_camera_from_matrix(c, NULL, HFVIS_CLIP_DEPTH_GL, 8, 8, 1, 1, d));
    BAD('Z', INV, hfvis_camera_from_matrix(c, gl, HFVIS_CLIP_DEPTH_GL, 0, 8, 1, 1, d));
    BAD('G', INV, hfvis_camera_from_matrix(c, gl, HFVIS_CLIP_DEPTH_GL, 8, 8, -1, 1, d));
    BAD('O', LIM, hfvis_camera_from_matrix(c, gl, HFVIS_CLIP_DEPTH_GL, HFVIS_SSAO_MAX_SIZE + 1, 8, 1, 1, d));
    BAD('E', INV, hfvis_camera_from_matrix(c, gl, (hfvis_clip_depth)0, 8, 8, 1, 1, d));
    BAD('E', INV, hfvis_camera_from_matrix(c, gl, (hfvis_clip_depth)3, 8, 8, 1, 1, d));
    memcpy(b, gl, sizeof b); b[10] = (double)NAN;
    BAD('F', INV, hfvis_camera_from_matrix(c, b, HFVIS_CLIP_DEPTH_GL, 8, 8, 1, 1, d));
    memcpy(b, gl, sizeof b); b[4] = 0.1; /* x-y shear */
    BAD('R', INV, hfvis_camera_from_matrix(c, b, HFVIS_CLIP_DEPTH_GL, 8, 8, 1, 1, d));
    memcpy(b, gl, sizeof b); b[10] = -1.0 + 1e-7; /* an epsilon-adjusted infinite far plane */
    BAD('R', INV, hfvis_camera_from_matrix(c, b, HFVIS_CLIP_DEPTH_GL, 8, 8, 1, 1, d));
    BAD('R', INV, hfvis_camera_from_matrix(c, gl, HFVIS_CLIP_DEPTH_GL, 8, 8, 4, 1, d));
}

static void args_camera_unproject(void)
{
    double *o;
    begin("camera_unproject");
    o = AD(3);
    OK(hfvis_camera_unproject(&cam_ok, 4.0, 4.0, 2.0, o));
    BAD('N', INV, hfvis_camera_unproject(NULL, 4.0, 4.0, 2.0, o));
    BAD('N', INV, hfvis_camera_unproject(&cam_ok, 4.0, 4.0, 2.0, NULL));
    BAD('F', INV, hfvis_camera_unproject(&cam_ok, (double)NAN, 4.0, 2.0, o));
    BAD('F', INV, hfvis_camera_unproject(&cam_ok, 4.0, 4.0, (double)INFINITY, o));
    CAMERA_CASES(hfvis_camera_unproject(&bc, 4.0, 4.0, 2.0, o));
}

static void args_camera_project(void)
{
    static const double p[3] = {0.1, 0.2, -2.0}, pb[3] = {0.1, 0.2, 1.0}, pn[3] = {(double)NAN, 0.2, -2.0};
    double *u, *v, *d;
    begin("camera_project");
    u = AD(1); v = AD(1); d = AD(1);
    OK(hfvis_camera_project(&cam_ok, p, u, v, d));
    BAD('N', INV, hfvis_camera_project(NULL, p, u, v, d));
    BAD('N', INV, hfvis_camera_project(&cam_ok, NULL, u, v, d));
    BAD('N', INV, hfvis_camera_project(&cam_ok, p, NULL, v, d));
    BAD('N', INV, hfvis_camera_project(&cam_ok, p, u, v, NULL));
    BAD('F', INV, hfvis_camera_project(&cam_ok, pn, u, v, d));
    BAD('R', INV, hfvis_camera_project(&cam_ok, pb, u, v, d));
    CAMERA_CASES(hfvis_camera_project(&bc, p, u, v, d));
}

static void args_depth_linear(void)
{
    begin("depth_linear");
    CHECK(isfinite(hfvis_depth_linear(0.5, HFVIS_DEPTH_GL, 0, 0.1, 10.0)));
    BADV('E', isnan(hfvis_depth_linear(0.5, (hfvis_depth_encoding)99, 0, 0.1, 10.0)));
    BADV('R', isnan(hfvis_depth_linear(0.5, HFVIS_DEPTH_GL, 2, 0.1, 10.0)));
    BADV('Z', isnan(hfvis_depth_linear(0.5, HFVIS_DEPTH_GL, 0, 0.0, 10.0)));
    BADV('F', isnan(hfvis_depth_linear(0.5, HFVIS_DEPTH_GL, 0, 0.1, (double)NAN)));
    BADV('F', hfvis_depth_linear((double)NAN, HFVIS_DEPTH_GL, 0, 0.1, 10.0) == (double)INFINITY);
    BADV('R', isnan(hfvis_depth_linear(0.5, HFVIS_DEPTH_INFINITE_FAR, 1, 0.1, 10.0)));
}

static void args_depth_hardware(void)
{
    begin("depth_hardware");
    CHECK(isfinite(hfvis_depth_hardware(2.0, HFVIS_DEPTH_GL, 0, 0.1, 10.0)));
    BADV('E', isnan(hfvis_depth_hardware(2.0, (hfvis_depth_encoding)0, 0, 0.1, 10.0)));
    BADV('R', isnan(hfvis_depth_hardware(2.0, HFVIS_DEPTH_GL, -1, 0.1, 10.0)));
    BADV('G', isnan(hfvis_depth_hardware(-2.0, HFVIS_DEPTH_GL, 0, 0.1, 10.0)));
    BADV('F', isnan(hfvis_depth_hardware(2.0, HFVIS_DEPTH_GL, 0, (double)INFINITY, 10.0)));
}

static void args_depth_linearize(void)
{
    static const float in[4] = {0.1f, 0.2f, 0.3f, 0.4f};
    float *out;
    begin("depth_linearize");
    out = AF(4);
    OK(hfvis_depth_linearize(in, 2, 2, 2, HFVIS_DEPTH_GL, 0, 0.1, 10.0, out, 2));
    BAD('N', INV, hfvis_depth_linearize(NULL, 2, 2, 2, HFVIS_DEPTH_GL, 0, 0.1, 10.0, out, 2));
    BAD('N', INV, hfvis_depth_linearize(in, 2, 2, 2, HFVIS_DEPTH_GL, 0, 0.1, 10.0, NULL, 2));
    BAD('Z', INV, hfvis_depth_linearize(in, 0, 2, 2, HFVIS_DEPTH_GL, 0, 0.1, 10.0, out, 2));
    BAD('G', INV, hfvis_depth_linearize(in, 2, -2, 2, HFVIS_DEPTH_GL, 0, 0.1, 10.0, out, 2));
    BAD('R', INV, hfvis_depth_linearize(in, 2, 2, 1, HFVIS_DEPTH_GL, 0, 0.1, 10.0, out, 2));
    BAD('R', INV, hfvis_depth_linearize(in, 2, 2, 2, HFVIS_DEPTH_GL, 0, 0.1, 10.0, out, 1));
    BAD('E', INV, hfvis_depth_linearize(in, 2, 2, 2, (hfvis_depth_encoding)99, 0, 0.1, 10.0, out, 2));
    BAD('R', INV, hfvis_depth_linearize(in, 2, 2, 2, HFVIS_DEPTH_GL, 3, 0.1, 10.0, out, 2));
    BAD('F', INV, hfvis_depth_linearize(in, 2, 2, 2, HFVIS_DEPTH_GL, 0, (double)NAN, 10.0, out, 2));
    BAD('R', INV, hfvis_depth_linearize(in, 2, 2, 2, HFVIS_DEPTH_GL, 0, 10.0, 0.1, out, 2));
    BAD('O', INV, hfvis_depth_linearize(in, 2, 3, PTRDIFF_MAX, HFVIS_DEPTH_GL, 0, 0.1, 10.0, out, 2));
}

static void args_depth_normals(void)
{
    float *n;
    begin("depth_normals");
    n = AF(3 * 64);
    OK(hfvis_depth_normals(&cam_ok, cam_depth, n));
    BAD('N', INV, hfvis_depth_normals(NULL, cam_depth, n));
    BAD('N', INV, hfvis_depth_normals(&cam_ok, NULL, n));
    BAD('N', INV, hfvis_depth_normals(&cam_ok, cam_depth, NULL));
    CAMERA_CASES(hfvis_depth_normals(&bc, cam_depth, n));
}

static void args_camera_line_plane(void)
{
    static const double ref[3] = {0.1, 0.1, -2.0}, rb[3] = {0.1, 0.1, 2.0}, rn[3] = {0.1, (double)NAN, -2.0};
    double *e1, *y;
    begin("camera_line_plane");
    e1 = AD(3); y = AD(3);
    OK(hfvis_camera_line_plane(&cam_ok, ref, 1.0, 0.0, e1, y));
    BAD('N', INV, hfvis_camera_line_plane(NULL, ref, 1.0, 0.0, e1, y));
    BAD('N', INV, hfvis_camera_line_plane(&cam_ok, NULL, 1.0, 0.0, e1, y));
    BAD('N', INV, hfvis_camera_line_plane(&cam_ok, ref, 1.0, 0.0, NULL, y));
    BAD('N', INV, hfvis_camera_line_plane(&cam_ok, ref, 1.0, 0.0, e1, NULL));
    BAD('Z', INV, hfvis_camera_line_plane(&cam_ok, ref, 0.0, 0.0, e1, y));
    BAD('F', INV, hfvis_camera_line_plane(&cam_ok, ref, (double)NAN, 0.0, e1, y));
    BAD('F', INV, hfvis_camera_line_plane(&cam_ok, rn, 1.0, 0.0, e1, y));
    BAD('R', INV, hfvis_camera_line_plane(&cam_ok, rb, 1.0, 0.0, e1, y));
    CAMERA_CASES(hfvis_camera_line_plane(&bc, ref, 1.0, 0.0, e1, y));
}

/* Invalid falloffs, substituted as bf (a struct value). */
#define FALLOFF_CASES(expr) do { hfvis_falloff bf; \
    memset(&bf, 0, sizeof bf); bf.kind = (hfvis_falloff_kind)99; BAD('E', INV, expr); \
    memset(&bf, 0, sizeof bf); bf.kind = HFVIS_FALLOFF_STEP; bf.param = 0.0; BAD('Z', INV, expr); \
    memset(&bf, 0, sizeof bf); bf.kind = HFVIS_FALLOFF_EXPONENTIAL; bf.param = (double)NAN; BAD('F', INV, expr); \
    memset(&bf, 0, sizeof bf); bf.kind = HFVIS_FALLOFF_HBAO; bf.param = 1.0; bf.hbao_c = -1.0; BAD('G', INV, expr); \
    memset(&bf, 0, sizeof bf); bf.kind = HFVIS_FALLOFF_CUSTOM; BAD('N', INV, expr); \
    } while (0)

static void args_falloff_check(void)
{
    hfvis_falloff f;
    begin("falloff_check");
    memset(&f, 0, sizeof f);
    OK(hfvis_falloff_check(&f));
    BAD('N', INV, hfvis_falloff_check(NULL));
    FALLOFF_CASES(hfvis_falloff_check(&bf));
}

static void args_falloff_eval(void)
{
    hfvis_falloff f;
    begin("falloff_eval");
    memset(&f, 0, sizeof f);
    f.kind = (hfvis_falloff_kind)99;
    CHECK(hfvis_falloff_eval(NULL, 1.0) == 1.0);
    BADV('E', isnan(hfvis_falloff_eval(&f, 1.0)));
    f.kind = HFVIS_FALLOFF_STEP; f.param = (double)NAN;
    BADV('F', isnan(hfvis_falloff_eval(&f, 1.0)));
}

static void args_falloff_support(void)
{
    hfvis_falloff f;
    begin("falloff_support");
    memset(&f, 0, sizeof f);
    CHECK(hfvis_falloff_support(NULL) == (double)INFINITY);
    f.kind = (hfvis_falloff_kind)-1;
    BADV('E', isnan(hfvis_falloff_support(&f)));
    f.kind = HFVIS_FALLOFF_STEP; f.param = -1.0;
    BADV('G', isnan(hfvis_falloff_support(&f)));
}

static void args_ssao_directions_uniform(void)
{
    hfvis_ssao_direction *d;
    begin("ssao_directions_uniform");
    d = ATN(hfvis_ssao_direction, 4);
    OK(hfvis_ssao_directions_uniform(4, 0.0, 1.0, 1.0, d));
    BAD('N', INV, hfvis_ssao_directions_uniform(4, 0.0, 1.0, 1.0, NULL));
    BAD('Z', INV, hfvis_ssao_directions_uniform(0, 0.0, 1.0, 1.0, d));
    BAD('G', INV, hfvis_ssao_directions_uniform(-4, 0.0, 1.0, 1.0, d));
    BAD('O', INV, hfvis_ssao_directions_uniform(HFVIS_SSAO_MAX_DIRECTIONS + 1, 0.0, 1.0, 1.0, d));
    BAD('F', INV, hfvis_ssao_directions_uniform(4, (double)NAN, 1.0, 1.0, d));
    BAD('F', INV, hfvis_ssao_directions_uniform(4, 0.0, (double)INFINITY, 1.0, d));
    BAD('R', INV, hfvis_ssao_directions_uniform(4, 0.0, 1.0, 1e-3, d));
}

static void args_ssao_directions_box(void)
{
    hfvis_ssao_direction *d;
    begin("ssao_directions_box");
    d = ATN(hfvis_ssao_direction, 8);
    OK(hfvis_ssao_directions_box(1, 1, 1.0, d));
    BAD('N', INV, hfvis_ssao_directions_box(1, 1, 1.0, NULL));
    BAD('Z', INV, hfvis_ssao_directions_box(0, 1, 1.0, d));
    BAD('G', INV, hfvis_ssao_directions_box(1, -1, 1.0, d));
    BAD('O', INV, hfvis_ssao_directions_box(1, 5000, 1.0, d));
    BAD('O', INV, hfvis_ssao_directions_box(HFVIS_SSAO_MAX_DIRECTIONS / 8 + 1, 1, 1.0, d));
    BAD('F', INV, hfvis_ssao_directions_box(1, 1, (double)NAN, d));
    BAD('R', INV, hfvis_ssao_directions_box(1, 1, 1e6, d));
}

static hfvis_ssao_direction dir_ok(void)
{
    hfvis_ssao_direction d;
    hfvis_ssao_directions_uniform(1, 0.3, 1.0, 1.0, &d);
    return d;
}

static void args_ssao_lattice_init(void)
{
    hfvis_ssao_direction d = dir_ok(), b;
    hfvis_ssao_lattice *L;
    begin("ssao_lattice_init");
    L = AT(hfvis_ssao_lattice);
    OK(hfvis_ssao_lattice_init(&cam_ok, &d, L));
    BAD('N', INV, hfvis_ssao_lattice_init(NULL, &d, L));
    BAD('N', INV, hfvis_ssao_lattice_init(&cam_ok, NULL, L));
    BAD('N', INV, hfvis_ssao_lattice_init(&cam_ok, &d, NULL));
    b = d; b.dx = (double)NAN; BAD('F', INV, hfvis_ssao_lattice_init(&cam_ok, &b, L));
    b = d; b.dx = 2.0; BAD('S', INV, hfvis_ssao_lattice_init(&cam_ok, &b, L));
    b = d; b.step = 0.0; BAD('Z', INV, hfvis_ssao_lattice_init(&cam_ok, &b, L));
    b = d; b.spacing = -1.0; BAD('G', INV, hfvis_ssao_lattice_init(&cam_ok, &b, L));
    b = d; b.step_x += 0.5; BAD('S', INV, hfvis_ssao_lattice_init(&cam_ok, &b, L));
    CAMERA_CASES(hfvis_ssao_lattice_init(&bc, &d, L));
}

static hfvis_ssao_direction bad_weight_dir; /* a valid direction with weight -1 (setup) */

static hfvis_ssao_lattice lat_ok;
static hfvis_ssao_line lines_ok[64];

static void make_lattice(void)
{
    hfvis_ssao_direction d = dir_ok();
    bad_weight_dir = d;
    bad_weight_dir.weight = -1.0;
    if (hfvis_ssao_lattice_init(&cam_ok, &d, &lat_ok) != HFVIS_OK || lat_ok.line_count > 64 ||
        hfvis_ssao_lattice_lines(&cam_ok, &lat_ok, lines_ok) != HFVIS_OK)
        exit(2);
}

static void args_ssao_lattice_lines(void)
{
    hfvis_ssao_line *ln;
    begin("ssao_lattice_lines");
    ln = ATN(hfvis_ssao_line, lat_ok.line_count);
    OK(hfvis_ssao_lattice_lines(&cam_ok, &lat_ok, ln));
    BAD('N', INV, hfvis_ssao_lattice_lines(NULL, &lat_ok, ln));
    BAD('N', INV, hfvis_ssao_lattice_lines(&cam_ok, NULL, ln));
    BAD('N', INV, hfvis_ssao_lattice_lines(&cam_ok, &lat_ok, NULL));
    CAMERA_CASES(hfvis_ssao_lattice_lines(&bc, &lat_ok, ln));
}

static void args_ssao_lattice_nearest(void)
{
    int *l, *s;
    begin("ssao_lattice_nearest");
    l = AT(int); s = AT(int);
    CHECK(hfvis_ssao_lattice_nearest(&lat_ok, lines_ok, 4.0, 4.0, NULL, NULL) == 0 ||
          hfvis_ssao_lattice_nearest(&lat_ok, lines_ok, 4.0, 4.0, l, s) == 1);
    BADV('N', hfvis_ssao_lattice_nearest(NULL, lines_ok, 4.0, 4.0, l, s) == 0);
    BADV('N', hfvis_ssao_lattice_nearest(&lat_ok, NULL, 4.0, 4.0, l, s) == 0);
    BADV('N', hfvis_ssao_lattice_nearest(&lat_ok, lines_ok, 4.0, 4.0, NULL, s) == 0);
    BADV('F', hfvis_ssao_lattice_nearest(&lat_ok, lines_ok, (double)NAN, 4.0, l, s) == 0);
}

static void args_lsao_options_default(void)
{
    hfvis_lsao_options o = hfvis_lsao_options_default();
    begin("lsao_options_default");
    CHECK(o.directions >= 0);
}

/* Invalid LSAO options, substituted as &bl. */
#define LSAO_OPT_CASES(expr) do { hfvis_lsao_options bl; \
    bl = hfvis_lsao_options_default(); bl.directions = -8; BAD('G', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.directions = HFVIS_SSAO_MAX_DIRECTIONS + 8; BAD('O', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.directions = 12; bl.pattern = HFVIS_SSAO_PATTERN_BOX; BAD('S', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.pattern = (hfvis_ssao_pattern)99; BAD('E', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.tangent = (hfvis_ssao_tangent)99; BAD('E', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.gather = (hfvis_ssao_gather)-1; BAD('E', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.pattern = HFVIS_SSAO_PATTERN_UNIFORM; bl.step = (double)NAN; BAD('F', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.fixed_sin_t = 2.0; BAD('S', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.reject_depth = (double)NAN; BAD('F', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.pattern = HFVIS_SSAO_PATTERN_CUSTOM; BAD('N', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.falloff.kind = (hfvis_falloff_kind)99; BAD('S', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.box_scale = -1; BAD('G', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.sampling = (hfvis_ssao_sampling)9; BAD('E', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.plane = (hfvis_ssao_plane)9; BAD('E', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.pop = (hfvis_lsao_pop)9; BAD('E', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.reject_normal = 1.5; BAD('S', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.azimuth0_rad = (double)INFINITY; bl.pattern = HFVIS_SSAO_PATTERN_UNIFORM; BAD('F', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.spacing = 1e9; BAD('O', INV, expr); \
    bl = hfvis_lsao_options_default(); bl.pattern = HFVIS_SSAO_PATTERN_CUSTOM; bl.directions = 1; \
    bl.custom_directions = &bad_weight_dir; BAD('S', INV, expr); \
    } while (0)

static void args_lsao_options_resolve(void)
{
    hfvis_lsao_options *o;
    begin("lsao_options_resolve");
    o = AT(hfvis_lsao_options);
    OK(hfvis_lsao_options_resolve(NULL, o));
    BAD('N', INV, hfvis_lsao_options_resolve(NULL, NULL));
    LSAO_OPT_CASES(hfvis_lsao_options_resolve(&bl, o));
}

static void args_lsao_directions(void)
{
    hfvis_ssao_direction *d;
    begin("lsao_directions");
    d = ATN(hfvis_ssao_direction, 16);
    OK(hfvis_lsao_directions(NULL, d));
    BAD('N', INV, hfvis_lsao_directions(NULL, NULL));
    LSAO_OPT_CASES(hfvis_lsao_directions(&bl, d));
}

static const double ls_x[3] = {0.0, 1.0, 2.0}, ls_y[3] = {-3.0, -2.5, -2.8};

static void args_lsao_line(void)
{
    int *st;
    double *o;
    begin("lsao_line");
    st = ATN(int, 3); o = AD(3);
    OK(hfvis_lsao_line(ls_x, ls_y, NULL, NULL, 3, 0, NULL, st, o));
    BAD('N', INV, hfvis_lsao_line(NULL, ls_y, NULL, NULL, 3, 0, NULL, st, o));
    BAD('N', INV, hfvis_lsao_line(ls_x, NULL, NULL, NULL, 3, 0, NULL, st, o));
    BAD('N', INV, hfvis_lsao_line(ls_x, ls_y, NULL, NULL, 3, 0, NULL, NULL, o));
    BAD('N', INV, hfvis_lsao_line(ls_x, ls_y, NULL, NULL, 3, 0, NULL, st, NULL));
    BAD('G', INV, hfvis_lsao_line(ls_x, ls_y, NULL, NULL, -1, 0, NULL, st, o));
    BAD('R', INV, hfvis_lsao_line(ls_x, ls_y, NULL, NULL, 3, 2, NULL, st, o));
    LSAO_OPT_CASES(hfvis_lsao_line(ls_x, ls_y, NULL, NULL, 3, 0, &bl, st, o));
}

static void args_lsao_line_naive(void)
{
    double *o;
    begin("lsao_line_naive");
    o = AD(3);
    OK(hfvis_lsao_line_naive(ls_x, ls_y, NULL, NULL, 3, 0, NULL, o));
    BAD('N', INV, hfvis_lsao_line_naive(NULL, ls_y, NULL, NULL, 3, 0, NULL, o));
    BAD('N', INV, hfvis_lsao_line_naive(ls_x, ls_y, NULL, NULL, 3, 0, NULL, NULL));
    BAD('G', INV, hfvis_lsao_line_naive(ls_x, ls_y, NULL, NULL, -1, 0, NULL, o));
    BAD('R', INV, hfvis_lsao_line_naive(ls_x, ls_y, NULL, NULL, 3, -1, NULL, o));
    LSAO_OPT_CASES(hfvis_lsao_line_naive(ls_x, ls_y, NULL, NULL, 3, 0, &bl, o));
}

/* Invalid lattices, substituted as &bk (lines_ok stays). */
#define LATTICE_CASES(expr) do { hfvis_ssao_lattice bk; \
    bk = lat_ok; bk.dir.dx = (double)NAN; BAD('F', INV, expr); \
    bk = lat_ok; bk.line_count = -1; BAD('G', INV, expr); \
    bk = lat_ok; bk.sample_count = 1; BAD('R', INV, expr); \
    bk = lat_ok; bk.max_line_samples = 0; BAD('Z', INV, expr); \
    } while (0)

static void args_lsao_direction(void)
{
    float *v, *sd;
    begin("lsao_direction");
    v = AF(lat_ok.sample_count); sd = AF(lat_ok.sample_count);
    OK(hfvis_lsao_direction(&cam_ok, cam_depth, cam_normals, NULL, &lat_ok, lines_ok, v, sd));
    OK(hfvis_lsao_direction(&cam_ok, cam_depth, NULL, NULL, &lat_ok, lines_ok, v, NULL));
    BAD('N', INV, hfvis_lsao_direction(NULL, cam_depth, cam_normals, NULL, &lat_ok, lines_ok, v, sd));
    BAD('N', INV, hfvis_lsao_direction(&cam_ok, NULL, cam_normals, NULL, &lat_ok, lines_ok, v, sd));
    BAD('N', INV, hfvis_lsao_direction(&cam_ok, cam_depth, cam_normals, NULL, NULL, lines_ok, v, sd));
    BAD('N', INV, hfvis_lsao_direction(&cam_ok, cam_depth, cam_normals, NULL, &lat_ok, NULL, v, sd));
    BAD('N', INV, hfvis_lsao_direction(&cam_ok, cam_depth, cam_normals, NULL, &lat_ok, lines_ok, NULL, sd));
    CAMERA_CASES(hfvis_lsao_direction(&bc, cam_depth, cam_normals, NULL, &lat_ok, lines_ok, v, sd));
    LSAO_OPT_CASES(hfvis_lsao_direction(&cam_ok, cam_depth, cam_normals, &bl, &lat_ok, lines_ok, v, sd));
    LATTICE_CASES(hfvis_lsao_direction(&cam_ok, cam_depth, cam_normals, NULL, &bk, lines_ok, v, sd));
}

static void args_lsao_direction_naive(void)
{
    float *v, *sd;
    begin("lsao_direction_naive");
    v = AF(lat_ok.sample_count); sd = AF(lat_ok.sample_count);
    OK(hfvis_lsao_direction_naive(&cam_ok, cam_depth, cam_normals, NULL, &lat_ok, lines_ok, v, sd));
    BAD('N', INV, hfvis_lsao_direction_naive(NULL, cam_depth, cam_normals, NULL, &lat_ok, lines_ok, v, sd));
    BAD('N', INV, hfvis_lsao_direction_naive(&cam_ok, NULL, cam_normals, NULL, &lat_ok, lines_ok, v, sd));
    BAD('N', INV, hfvis_lsao_direction_naive(&cam_ok, cam_depth, cam_normals, NULL, NULL, lines_ok, v, sd));
    BAD('N', INV, hfvis_lsao_direction_naive(&cam_ok, cam_depth, cam_normals, NULL, &lat_ok, NULL, v, sd));
    BAD('N', INV, hfvis_lsao_direction_naive(&cam_ok, cam_depth, cam_normals, NULL, &lat_ok, lines_ok, NULL, sd));
    CAMERA_CASES(hfvis_lsao_direction_naive(&bc, cam_depth, cam_normals, NULL, &lat_ok, lines_ok, v, sd));
    LSAO_OPT_CASES(hfvis_lsao_direction_naive(&cam_ok, cam_depth, cam_normals, &bl, &lat_ok, lines_ok, v, sd));
    LATTICE_CASES(hfvis_lsao_direction_naive(&cam_ok, cam_depth, cam_normals, NULL, &bk, lines_ok, v, sd));
}

static float lat_vals[4096], lat_sd[4096];

static void args_lsao_gather(void)
{
    double *sum, *w;
    begin("lsao_gather");
    CHECK(lat_ok.sample_count <= 4096 &&
          hfvis_lsao_direction(&cam_ok, cam_depth, NULL, NULL, &lat_ok, lines_ok, lat_vals, lat_sd) == HFVIS_OK);
    sum = AD(INNER * INNER); w = AD(INNER * INNER);
    OK(hfvis_lsao_gather(&cam_ok, cam_depth, NULL, NULL, &lat_ok, lines_ok, lat_vals, lat_sd, sum, w));
    BAD('N', INV, hfvis_lsao_gather(NULL, cam_depth, NULL, NULL, &lat_ok, lines_ok, lat_vals, lat_sd, sum, w));
    BAD('N', INV, hfvis_lsao_gather(&cam_ok, NULL, NULL, NULL, &lat_ok, lines_ok, lat_vals, lat_sd, sum, w));
    BAD('N', INV, hfvis_lsao_gather(&cam_ok, cam_depth, NULL, NULL, NULL, lines_ok, lat_vals, lat_sd, sum, w));
    BAD('N', INV, hfvis_lsao_gather(&cam_ok, cam_depth, NULL, NULL, &lat_ok, NULL, lat_vals, lat_sd, sum, w));
    BAD('N', INV, hfvis_lsao_gather(&cam_ok, cam_depth, NULL, NULL, &lat_ok, lines_ok, NULL, lat_sd, sum, w));
    BAD('N', INV, hfvis_lsao_gather(&cam_ok, cam_depth, NULL, NULL, &lat_ok, lines_ok, lat_vals, NULL, sum, w));
    BAD('N', INV, hfvis_lsao_gather(&cam_ok, cam_depth, NULL, NULL, &lat_ok, lines_ok, lat_vals, lat_sd, NULL, w));
    BAD('N', INV, hfvis_lsao_gather(&cam_ok, cam_depth, NULL, NULL, &lat_ok, lines_ok, lat_vals, lat_sd, sum, NULL));
    CAMERA_CASES(hfvis_lsao_gather(&bc, cam_depth, NULL, NULL, &lat_ok, lines_ok, lat_vals, lat_sd, sum, w));
    LSAO_OPT_CASES(hfvis_lsao_gather(&cam_ok, cam_depth, NULL, &bl, &lat_ok, lines_ok, lat_vals, lat_sd, sum, w));
}

/* The shared checks of the whole-image AO routines: fn(cam, depth, normals, opts, ao, stride). */
#define AO_IMAGE_CASES(fn, optp) do { \
    BAD('N', INV, fn(NULL, cam_depth, cam_normals, optp, ao, INNER)); \
    BAD('N', INV, fn(&cam_ok, NULL, cam_normals, optp, ao, INNER)); \
    BAD('N', INV, fn(&cam_ok, cam_depth, cam_normals, optp, NULL, INNER)); \
    BAD('R', INV, fn(&cam_ok, cam_depth, cam_normals, optp, ao, INNER - 1)); \
    BAD('O', INV, fn(&cam_ok, cam_depth, cam_normals, optp, ao, PTRDIFF_MAX)); \
    CAMERA_CASES(fn(&bc, cam_depth, cam_normals, optp, ao, INNER)); \
    } while (0)

static void args_lsao(void)
{
    float *ao;
    begin("lsao");
    ao = AF(INNER * INNER);
    OK(hfvis_lsao(&cam_ok, cam_depth, cam_normals, NULL, ao, INNER));
    AO_IMAGE_CASES(hfvis_lsao, NULL);
    LSAO_OPT_CASES(hfvis_lsao(&cam_ok, cam_depth, cam_normals, &bl, ao, INNER));
}

static void args_hbao_options_default(void)
{
    hfvis_hbao_options o = hfvis_hbao_options_default();
    begin("hbao_options_default");
    CHECK(o.directions >= 0);
}

#define HBAO_OPT_CASES(expr) do { hfvis_hbao_options bh; \
    bh = hfvis_hbao_options_default(); bh.directions = -1; BAD('G', INV, expr); \
    bh = hfvis_hbao_options_default(); bh.directions = HFVIS_SSAO_MAX_DIRECTIONS + 1; BAD('O', INV, expr); \
    bh = hfvis_hbao_options_default(); bh.steps = -1; BAD('G', INV, expr); \
    bh = hfvis_hbao_options_default(); bh.radius = (double)NAN; BAD('F', INV, expr); \
    bh = hfvis_hbao_options_default(); bh.step_px = (double)INFINITY; BAD('F', INV, expr); \
    bh = hfvis_hbao_options_default(); bh.variant = (hfvis_hbao_variant)99; BAD('E', INV, expr); \
    bh = hfvis_hbao_options_default(); bh.jitter = (hfvis_hbao_jitter)-1; BAD('E', INV, expr); \
    bh = hfvis_hbao_options_default(); bh.tangent = HFVIS_SSAO_TANGENT_FIXED_HULL_REAL_EVAL; BAD('S', INV, expr); \
    bh = hfvis_hbao_options_default(); bh.fixed_sin_t = -1.5; BAD('S', INV, expr); \
    bh = hfvis_hbao_options_default(); bh.max_radius_px = -1.0; BAD('G', INV, expr); \
    bh = hfvis_hbao_options_default(); bh.sampling = (hfvis_ssao_sampling)9; BAD('E', INV, expr); \
    bh = hfvis_hbao_options_default(); bh.plane = (hfvis_ssao_plane)9; BAD('E', INV, expr); \
    bh = hfvis_hbao_options_default(); bh.falloff.kind = HFVIS_FALLOFF_STEP; BAD('S', INV, expr); \
    bh = hfvis_hbao_options_default(); bh.azimuth0_rad = (double)NAN; BAD('F', INV, expr); \
    } while (0)

static void args_hbao_options_resolve(void)
{
    hfvis_hbao_options *o;
    begin("hbao_options_resolve");
    o = AT(hfvis_hbao_options);
    OK(hfvis_hbao_options_resolve(NULL, o));
    BAD('N', INV, hfvis_hbao_options_resolve(NULL, NULL));
    HBAO_OPT_CASES(hfvis_hbao_options_resolve(&bh, o));
}

static void args_hbao(void)
{
    float *ao;
    begin("hbao");
    ao = AF(INNER * INNER);
    OK(hfvis_hbao(&cam_ok, cam_depth, cam_normals, NULL, ao, INNER));
    AO_IMAGE_CASES(hfvis_hbao, NULL);
    HBAO_OPT_CASES(hfvis_hbao(&cam_ok, cam_depth, cam_normals, &bh, ao, INNER));
}

static void args_ssao_rt_options_default(void)
{
    hfvis_ssao_rt_options o = hfvis_ssao_rt_options_default();
    begin("ssao_rt_options_default");
    CHECK(o.rays >= 0);
}

#define RT_OPT_CASES(expr) do { hfvis_ssao_rt_options br; \
    br = hfvis_ssao_rt_options_default(); br.rays = -1; BAD('G', INV, expr); \
    br = hfvis_ssao_rt_options_default(); br.refine_iterations = 65; BAD('O', INV, expr); \
    br = hfvis_ssao_rt_options_default(); br.thickness = (double)NAN; BAD('F', INV, expr); \
    br = hfvis_ssao_rt_options_default(); br.bias = -1.0; BAD('G', INV, expr); \
    br = hfvis_ssao_rt_options_default(); br.max_distance = (double)INFINITY; BAD('F', INV, expr); \
    br = hfvis_ssao_rt_options_default(); br.sampling = (hfvis_ssao_sampling)99; BAD('E', INV, expr); \
    br = hfvis_ssao_rt_options_default(); br.falloff.kind = (hfvis_falloff_kind)99; BAD('S', INV, expr); \
    } while (0)

static void args_ssao_rt_options_resolve(void)
{
    hfvis_ssao_rt_options *o;
    begin("ssao_rt_options_resolve");
    o = AT(hfvis_ssao_rt_options);
    OK(hfvis_ssao_rt_options_resolve(NULL, o));
    BAD('N', INV, hfvis_ssao_rt_options_resolve(NULL, NULL));
    RT_OPT_CASES(hfvis_ssao_rt_options_resolve(&br, o));
}

static void args_ssao_reference(void)
{
    hfvis_ssao_rt_options o = hfvis_ssao_rt_options_default();
    float *ao;
    begin("ssao_reference");
    o.rays = 4;
    ao = AF(INNER * INNER);
    OK(hfvis_ssao_reference(&cam_ok, cam_depth, cam_normals, &o, ao, INNER));
    AO_IMAGE_CASES(hfvis_ssao_reference, &o);
    RT_OPT_CASES(hfvis_ssao_reference(&cam_ok, cam_depth, cam_normals, &br, ao, INNER));
}

static void args_ssao_scene_render(void)
{
    hfvis_ssao_scene sc, b;
    float *d, *n;
    begin("ssao_scene_render");
    d = AF(64); n = AF(3 * 64);
    memset(&sc, 0, sizeof sc);
    sc.kind = HFVIS_SSAO_SCENE_PIT; sc.base_depth = 4.0; sc.radius = 1.0;
    OK(hfvis_ssao_scene_render(&cam_ok, &sc, d, n));
    OK(hfvis_ssao_scene_render(&cam_ok, &sc, d, NULL));
    BAD('N', INV, hfvis_ssao_scene_render(NULL, &sc, d, n));
    BAD('N', INV, hfvis_ssao_scene_render(&cam_ok, NULL, d, n));
    BAD('N', INV, hfvis_ssao_scene_render(&cam_ok, &sc, NULL, n));
    b = sc; b.kind = (hfvis_ssao_scene_kind)99; BAD('E', INV, hfvis_ssao_scene_render(&cam_ok, &b, d, n));
    b = sc; b.base_depth = 0.0; BAD('Z', INV, hfvis_ssao_scene_render(&cam_ok, &b, d, n));
    b = sc; b.radius = -1.0; BAD('G', INV, hfvis_ssao_scene_render(&cam_ok, &b, d, n));
    b = sc; b.x0 = (double)NAN; BAD('F', INV, hfvis_ssao_scene_render(&cam_ok, &b, d, n));
    b = sc; b.kind = HFVIS_SSAO_SCENE_VGROOVE; b.angle = 2.0; BAD('S', INV, hfvis_ssao_scene_render(&cam_ok, &b, d, n));
    CAMERA_CASES(hfvis_ssao_scene_render(&bc, &sc, d, n));
}

static void args_ffao_options_default(void)
{
    hfvis_ffao_options o = hfvis_ffao_options_default();
    begin("ffao_options_default");
    CHECK(o.directions >= 0);
}

#define FFAO_OPT_CASES(expr) do { hfvis_ffao_options bq; \
    bq = hfvis_ffao_options_default(); bq.directions = 2; BAD('R', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.directions = -1; BAD('G', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.segments = 65; BAD('O', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.b0 = 5000; BAD('O', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.azimuth0_rad = (double)NAN; BAD('F', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.receiver_slope = 1.0; BAD('S', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.thickness = (double)INFINITY; BAD('F', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.estimator = (hfvis_ffao_estimator)99; BAD('E', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.near_field = (hfvis_ffao_near)-1; BAD('E', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.mip_growth = 0.5; BAD('S', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.levels = -1; BAD('G', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.quad_nodes = 65; BAD('O', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.blur_radius = -1; BAD('G', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.sparse = 1; bq.directions = 8; BAD('S', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.averaging = (hfvis_ffao_averaging)9; BAD('E', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.sampling = (hfvis_ssao_sampling)9; BAD('E', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.level_gamma = (double)NAN; BAD('F', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.blur_threshold = (double)INFINITY; BAD('F', INV, expr); \
    bq = hfvis_ffao_options_default(); bq.estimator = HFVIS_FFAO_L_CLOSED_FORM; bq.falloff.kind = HFVIS_FALLOFF_STEP; \
    bq.falloff.param = 1.0; BAD('S', INV, expr); \
    } while (0)

static void args_ffao_options_resolve(void)
{
    hfvis_ffao_options *o;
    begin("ffao_options_resolve");
    o = AT(hfvis_ffao_options);
    OK(hfvis_ffao_options_resolve(NULL, o));
    BAD('N', INV, hfvis_ffao_options_resolve(NULL, NULL));
    FFAO_OPT_CASES(hfvis_ffao_options_resolve(&bq, o));
}

static void args_ffao_slab_integral(void)
{
    hfvis_falloff f;
    begin("ffao_slab_integral");
    memset(&f, 0, sizeof f);
    CHECK(isfinite(hfvis_ffao_slab_integral(&f, 0.2, 1.0, 1.0, 2.0, 0.0, 8)));
    BADV('Z', isnan(hfvis_ffao_slab_integral(&f, 0.2, 1.0, 1.0, 2.0, 0.0, 0)));
    BADV('O', isnan(hfvis_ffao_slab_integral(&f, 0.2, 1.0, 1.0, 2.0, 0.0, 65)));
    BADV('F', isnan(hfvis_ffao_slab_integral(&f, (double)NAN, 1.0, 1.0, 2.0, 0.0, 8)));
    f.kind = (hfvis_falloff_kind)99;
    BADV('E', isnan(hfvis_ffao_slab_integral(&f, 0.2, 1.0, 1.0, 2.0, 0.0, 8)));
}

static void args_ffao_slab_rho1(void)
{
    begin("ffao_slab_rho1");
    CHECK(isfinite(hfvis_ffao_slab_rho1(0.2, 1.0, 2.0, 0.0)));
    BADV('F', isnan(hfvis_ffao_slab_rho1((double)NAN, 1.0, 2.0, 0.0)));
    BADV('F', isnan(hfvis_ffao_slab_rho1(0.2, (double)NAN, 2.0, 0.0)));
    BADV('F', isnan(hfvis_ffao_slab_rho1(0.2, 1.0, (double)INFINITY, 0.0)));
}

static void args_ffao_table_build(void)
{
    hfvis_falloff f;
    hfvis_ffao_table *t;
    begin("ffao_table_build");
    memset(&f, 0, sizeof f);
    t = AT(hfvis_ffao_table);
    arena_fill();
    base_status(hfvis_ffao_table_build(&f, 2, 2, 2, 2, 1.0, NULL, t), __LINE__);
    hfvis_ffao_table_free(t);
    BAD('N', INV, hfvis_ffao_table_build(&f, 2, 2, 2, 2, 1.0, NULL, NULL));
    BAD('R', INV, hfvis_ffao_table_build(&f, 1, 2, 2, 2, 1.0, NULL, t));
    BAD('G', INV, hfvis_ffao_table_build(&f, 2, -2, 2, 2, 1.0, NULL, t));
    BAD('O', INV, hfvis_ffao_table_build(&f, 2, 2, 4097, 2, 1.0, NULL, t));
    BAD('F', INV, hfvis_ffao_table_build(&f, 2, 2, 2, 2, (double)NAN, NULL, t));
    BAD('G', INV, hfvis_ffao_table_build(&f, 2, 2, 2, 2, -1.0, NULL, t));
    FALLOFF_CASES(hfvis_ffao_table_build(&bf, 2, 2, 2, 2, 1.0, NULL, t));
}

static void args_ffao_table_free(void)
{
    hfvis_ffao_table t;
    begin("ffao_table_free");
    memset(&t, 0, sizeof t);
    hfvis_ffao_table_free(NULL);
    hfvis_ffao_table_free(&t);
    BADV('N', t.values == NULL);
}

static void args_ffao_table_lookup(void)
{
    hfvis_ffao_table t;
    hfvis_falloff f;
    begin("ffao_table_lookup");
    memset(&f, 0, sizeof f);
    CHECK(hfvis_ffao_table_build(&f, 2, 2, 2, 2, 1.0, NULL, &t) == HFVIS_OK);
    CHECK(isfinite(hfvis_ffao_table_lookup(&t, 0.5, 1.0, 2.0, 0.0)));
    BADV('N', isnan(hfvis_ffao_table_lookup(NULL, 0.5, 1.0, 2.0, 0.0)));
    BADV('F', isnan(hfvis_ffao_table_lookup(&t, (double)NAN, 1.0, 2.0, 0.0)));
    t.na = 0;
    BADV('S', isnan(hfvis_ffao_table_lookup(&t, 0.5, 1.0, 2.0, 0.0)));
    t.na = 2;
    hfvis_ffao_table_free(&t);
}

static void args_ffao_virtual_point(void)
{
    double h[2] = {7.0, 7.0};
    begin("ffao_virtual_point");
    hfvis_ffao_virtual_point(1.0, 0.5, -1.0, 2.0, h); /* h = ((m0 - m1)/slope, m0 zscale) */
    CHECK(h[0] == -0.5 && h[1] == 2.0);
    hfvis_ffao_virtual_point(1.0, 0.5, -1.0, 1.0, NULL);
    BADV('N', h[0] == -0.5 && h[1] == 2.0);
}

static void args_ffao_sector_weight(void)
{
    static const double p[3] = {0.1, 0.1, -2.0}, pb[3] = {0.1, 0.1, 2.0};
    begin("ffao_sector_weight");
    CHECK(isfinite(hfvis_ffao_sector_weight(&cam_ok, p, 0.0, 1.0)));
    BADV('N', isnan(hfvis_ffao_sector_weight(NULL, p, 0.0, 1.0)));
    BADV('N', isnan(hfvis_ffao_sector_weight(&cam_ok, NULL, 0.0, 1.0)));
    BADV('R', isnan(hfvis_ffao_sector_weight(&cam_ok, pb, 0.0, 1.0)));
    BADV('R', isnan(hfvis_ffao_sector_weight(&cam_ok, p, 1.0, 0.5)));
    BADV('F', isnan(hfvis_ffao_sector_weight(&cam_ok, p, (double)NAN, 1.0)));
}

static void args_ffao_slice(void)
{
    static const double p[2] = {0.0, -3.0}, n[2] = {0.0, 1.0}, pn[2] = {(double)NAN, -3.0}, pe[2] = {0.0, 0.0};
    static const double hx[2] = {1.0, 2.0}, hy[2] = {-2.5, -2.0};
    double *ob, *tm;
    begin("ffao_slice");
    ob = AD(1); tm = AD(1);
    OK(hfvis_ffao_slice(p, n, hx, hy, 2, 0, 3.14159, NULL, ob, tm));
    BAD('N', INV, hfvis_ffao_slice(NULL, n, hx, hy, 2, 0, 3.14159, NULL, ob, tm));
    BAD('N', INV, hfvis_ffao_slice(p, NULL, hx, hy, 2, 0, 3.14159, NULL, ob, tm));
    BAD('N', INV, hfvis_ffao_slice(p, n, NULL, hy, 2, 0, 3.14159, NULL, ob, tm));
    BAD('N', INV, hfvis_ffao_slice(p, n, hx, hy, 2, 0, 3.14159, NULL, NULL, tm));
    BAD('G', INV, hfvis_ffao_slice(p, n, hx, hy, -1, 0, 3.14159, NULL, ob, tm));
    BAD('R', INV, hfvis_ffao_slice(p, n, hx, hy, 2, 2, 3.14159, NULL, ob, tm));
    BAD('F', INV, hfvis_ffao_slice(pn, n, hx, hy, 2, 0, 3.14159, NULL, ob, tm));
    BAD('R', INV, hfvis_ffao_slice(pe, n, hx, hy, 2, 0, 3.14159, NULL, ob, tm));
    FFAO_OPT_CASES(hfvis_ffao_slice(p, n, hx, hy, 2, 0, 3.14159, &bq, ob, tm));
    {   /* the slice needs the table itself (hfvis_ffao builds one per call) */
        hfvis_ffao_options bq = hfvis_ffao_options_default();
        bq.estimator = HFVIS_FFAO_L_TABLE;
        BAD('N', INV, hfvis_ffao_slice(p, n, hx, hy, 2, 0, 3.14159, &bq, ob, tm));
    }
}

static void args_ffao(void)
{
    float *ao;
    begin("ffao");
    ao = AF(INNER * INNER);
    OK(hfvis_ffao(&cam_ok, cam_depth, cam_normals, NULL, ao, INNER));
    AO_IMAGE_CASES(hfvis_ffao, NULL);
    FFAO_OPT_CASES(hfvis_ffao(&cam_ok, cam_depth, cam_normals, &bq, ao, INNER));
}

static void args_ssao_mipmap(void)
{
    float *ao;
    begin("ssao_mipmap");
    ao = AF(INNER * INNER);
    OK(hfvis_ssao_mipmap(&cam_ok, cam_depth, cam_normals, NULL, ao, INNER));
    AO_IMAGE_CASES(hfvis_ssao_mipmap, NULL);
    FFAO_OPT_CASES(hfvis_ssao_mipmap(&cam_ok, cam_depth, cam_normals, &bq, ao, INNER));
}

static void args_ssao_bilateral_blur(void)
{
    static const float in[16] = {0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f, 0.8f, 0.9f, 0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f, 0.7f};
    float *out;
    begin("ssao_bilateral_blur");
    out = AF(16);
    OK(hfvis_ssao_bilateral_blur(in, 4, 4, 4, 2, 0.07, out, 4));
    BAD('N', INV, hfvis_ssao_bilateral_blur(NULL, 4, 4, 4, 2, 0.07, out, 4));
    BAD('N', INV, hfvis_ssao_bilateral_blur(in, 4, 4, 4, 2, 0.07, NULL, 4));
    BAD('R', INV, hfvis_ssao_bilateral_blur(out, 4, 4, 4, 2, 0.07, out, 4));
    BAD('Z', INV, hfvis_ssao_bilateral_blur(in, 4, 0, 4, 2, 0.07, out, 4));
    BAD('G', INV, hfvis_ssao_bilateral_blur(in, 4, 4, -4, 2, 0.07, out, 4));
    BAD('R', INV, hfvis_ssao_bilateral_blur(in, 3, 4, 4, 2, 0.07, out, 4));
    BAD('R', INV, hfvis_ssao_bilateral_blur(in, 4, 4, 4, 2, 0.07, out, 3));
    BAD('O', INV, hfvis_ssao_bilateral_blur(in, 4, 4, 4, 65, 0.07, out, 4));
    BAD('G', INV, hfvis_ssao_bilateral_blur(in, 4, 4, 4, -1, 0.07, out, 4));
    BAD('F', INV, hfvis_ssao_bilateral_blur(in, 4, 4, 4, 2, (double)NAN, out, 4));
    BAD('O', INV, hfvis_ssao_bilateral_blur(in, PTRDIFF_MAX, 4, 4, 2, 0.07, out, 4));
}

static void args_ssao_error(void)
{
    static const float a[4] = {0.1f, 0.2f, 0.3f, 0.4f}, r[4] = {0.1f, 0.25f, 0.3f, 0.5f};
    hfvis_ssao_error_stats *st;
    float *img;
    begin("ssao_error");
    st = AT(hfvis_ssao_error_stats); img = AF(4);
    OK(hfvis_ssao_error(a, 2, r, 2, 2, 2, 0.05, 0, st, img, 2));
    OK(hfvis_ssao_error(a, 2, r, 2, 2, 2, 0.05, 1, st, NULL, 0));
    BAD('N', INV, hfvis_ssao_error(NULL, 2, r, 2, 2, 2, 0.05, 0, st, img, 2));
    BAD('N', INV, hfvis_ssao_error(a, 2, NULL, 2, 2, 2, 0.05, 0, st, img, 2));
    BAD('N', INV, hfvis_ssao_error(a, 2, r, 2, 2, 2, 0.05, 0, NULL, img, 2));
    BAD('Z', INV, hfvis_ssao_error(a, 2, r, 2, 0, 2, 0.05, 0, st, img, 2));
    BAD('G', INV, hfvis_ssao_error(a, 2, r, 2, 2, -2, 0.05, 0, st, img, 2));
    BAD('R', INV, hfvis_ssao_error(a, 1, r, 2, 2, 2, 0.05, 0, st, img, 2));
    BAD('R', INV, hfvis_ssao_error(a, 2, r, 2, 2, 2, 0.05, 0, st, img, 1));
    BAD('G', INV, hfvis_ssao_error(a, 2, r, 2, 2, 2, -0.05, 0, st, img, 2));
    BAD('F', INV, hfvis_ssao_error(a, 2, r, 2, 2, 2, (double)INFINITY, 0, st, img, 2));
    BAD('R', INV, hfvis_ssao_error(a, 2, r, 2, 2, 2, 0.05, 2, st, img, 2));
    BAD('O', INV, hfvis_ssao_error(a, 2, r, PTRDIFF_MAX, 2, 2, 0.05, 0, st, img, 2));
}

/* ========================================================================================== */
/* voxel.c: matrices, views, volumes, meshes, OBJ, rasterizer, BVH, voxelizers, IV            */
/* ========================================================================================== */

static const uint32_t bad_idx[3] = {0, 1, 99};
static const float nan_xyz[9] = {0, 0, 0, 1, 0, 0, 0, (double)NAN, 0};
static const uint32_t tri_idx[3] = {0, 1, 2};

/* Invalid meshes, substituted as &bm; huge_status is what a triangle count past the limits gives. */
#define MESH_CASES(expr, huge_status) do { hfvis_mesh bm; \
    bm = m_box; bm.xyz = NULL; BAD('N', INV, expr); \
    bm = m_box; bm.indices = NULL; BAD('N', INV, expr); \
    bm = m_box; bm.indices = bad_idx; bm.triangle_count = 1; BAD('R', INV, expr); \
    bm.xyz = nan_xyz; bm.vertex_count = 3; bm.indices = tri_idx; bm.triangle_count = 1; BAD('F', INV, expr); \
    bm = m_box; bm.triangle_count = SIZE_MAX / 2; BAD('O', huge_status, expr); \
    bm = m_box; bm.vertex_count = SIZE_MAX / 2; BAD('O', INV, expr); \
    } while (0)

/* Invalid volume grids, substituted as &bv. */
#define VGRID_CASES(expr, huge_status) do { hfvis_volume_grid bv; \
    bv = vg_ok; bv.dims[0] = 0; BAD('Z', INV, expr); \
    bv = vg_ok; bv.dims[1] = -2; BAD('G', INV, expr); \
    bv = vg_ok; bv.cell[2] = 0.0; BAD('Z', INV, expr); \
    bv = vg_ok; bv.cell[0] = (double)NAN; BAD('F', INV, expr); \
    bv = vg_ok; bv.origin[1] = (double)INFINITY; BAD('F', INV, expr); \
    bv = vg_ok; bv.dims[0] = bv.dims[1] = bv.dims[2] = 2048; BAD('O', huge_status, expr); \
    } while (0)

static void args_mesh_free(void)
{
    hfvis_mesh m;
    begin("mesh_free");
    memset(&m, 0, sizeof m);
    hfvis_mesh_free(NULL, NULL);
    hfvis_mesh_free(NULL, &m);
    BADV('N', m.xyz == NULL);
}

static void args_mat4_multiply(void)
{
    double a[16] = {0}, o[16];
    begin("mat4_multiply");
    a[0] = a[5] = a[10] = a[15] = 1.0;
    hfvis_mat4_multiply(a, a, o);
    CHECK(o[0] == 1.0);
    hfvis_mat4_multiply(a, a, a); /* out may alias */
    CHECK(a[15] == 1.0);
}

static void args_mat4_invert(void)
{
    double m[16] = {0}, z[16] = {0}, n[16];
    double *o;
    begin("mat4_invert");
    o = AD(16);
    m[0] = m[5] = m[10] = m[15] = 2.0;
    OK(hfvis_mat4_invert(m, o));
    BAD('N', INV, hfvis_mat4_invert(NULL, o));
    BAD('N', INV, hfvis_mat4_invert(m, NULL));
    BAD('Z', INV, hfvis_mat4_invert(z, o));
    memcpy(n, m, sizeof n); n[3] = (double)NAN;
    BAD('F', INV, hfvis_mat4_invert(n, o));
}

static const double eye_ok[3] = {0, -3, 0}, tgt_ok[3] = {0, 0, 0}, up_ok[3] = {0, 0, 1};

static void args_mat4_look_at(void)
{
    double *o;
    begin("mat4_look_at");
    o = AD(16);
    OK(hfvis_mat4_look_at(eye_ok, tgt_ok, up_ok, o));
    BAD('N', INV, hfvis_mat4_look_at(NULL, tgt_ok, up_ok, o));
    BAD('N', INV, hfvis_mat4_look_at(eye_ok, NULL, up_ok, o));
    BAD('N', INV, hfvis_mat4_look_at(eye_ok, tgt_ok, NULL, o));
    BAD('N', INV, hfvis_mat4_look_at(eye_ok, tgt_ok, up_ok, NULL));
    BAD('R', INV, hfvis_mat4_look_at(tgt_ok, tgt_ok, up_ok, o));
    BAD('Z', INV, hfvis_mat4_look_at(eye_ok, tgt_ok, v3_zero, o));
    BAD('F', INV, hfvis_mat4_look_at(v3_nan, tgt_ok, up_ok, o));
}

static void args_mat4_perspective(void)
{
    double *o;
    begin("mat4_perspective");
    o = AD(16);
    OK(hfvis_mat4_perspective(1.0, 1.5, 0.1, 10.0, o));
    BAD('N', INV, hfvis_mat4_perspective(1.0, 1.5, 0.1, 10.0, NULL));
    BAD('Z', INV, hfvis_mat4_perspective(0.0, 1.5, 0.1, 10.0, o));
    BAD('R', INV, hfvis_mat4_perspective(3.2, 1.5, 0.1, 10.0, o));
    BAD('G', INV, hfvis_mat4_perspective(1.0, -1.5, 0.1, 10.0, o));
    BAD('Z', INV, hfvis_mat4_perspective(1.0, 1.5, 0.0, 10.0, o));
    BAD('R', INV, hfvis_mat4_perspective(1.0, 1.5, 10.0, 0.1, o));
    BAD('F', INV, hfvis_mat4_perspective(1.0, 1.5, 0.1, (double)INFINITY, o));
    BAD('F', INV, hfvis_mat4_perspective((double)NAN, 1.5, 0.1, 10.0, o));
}

static void args_mat4_ortho(void)
{
    double *o;
    begin("mat4_ortho");
    o = AD(16);
    OK(hfvis_mat4_ortho(-1, 1, -1, 1, 0.1, 10.0, o));
    BAD('N', INV, hfvis_mat4_ortho(-1, 1, -1, 1, 0.1, 10.0, NULL));
    BAD('R', INV, hfvis_mat4_ortho(1, -1, -1, 1, 0.1, 10.0, o));
    BAD('R', INV, hfvis_mat4_ortho(-1, 1, 1, 1, 0.1, 10.0, o));
    BAD('R', INV, hfvis_mat4_ortho(-1, 1, -1, 1, 10.0, 0.1, o));
    BAD('F', INV, hfvis_mat4_ortho((double)NAN, 1, -1, 1, 0.1, 10.0, o));
    BAD('F', INV, hfvis_mat4_ortho(-1, 1, -1, (double)INFINITY, 0.1, 10.0, o));
}

static void args_view_perspective(void)
{
    hfvis_view *v;
    begin("view_perspective");
    v = AT(hfvis_view);
    OK(hfvis_view_perspective(v, eye_ok, tgt_ok, up_ok, 1.0, 8, 8, 0.1, 10.0));
    BAD('N', INV, hfvis_view_perspective(NULL, eye_ok, tgt_ok, up_ok, 1.0, 8, 8, 0.1, 10.0));
    BAD('N', INV, hfvis_view_perspective(v, NULL, tgt_ok, up_ok, 1.0, 8, 8, 0.1, 10.0));
    BAD('Z', INV, hfvis_view_perspective(v, eye_ok, tgt_ok, up_ok, 1.0, 0, 8, 0.1, 10.0));
    BAD('G', INV, hfvis_view_perspective(v, eye_ok, tgt_ok, up_ok, 1.0, 8, -8, 0.1, 10.0));
    BAD('F', INV, hfvis_view_perspective(v, eye_ok, tgt_ok, up_ok, (double)NAN, 8, 8, 0.1, 10.0));
    BAD('R', INV, hfvis_view_perspective(v, eye_ok, tgt_ok, up_ok, 1.0, 8, 8, 10.0, 0.1));
    BAD('R', INV, hfvis_view_perspective(v, eye_ok, eye_ok, up_ok, 1.0, 8, 8, 0.1, 10.0));
}

static void args_view_orthographic(void)
{
    hfvis_view *v;
    begin("view_orthographic");
    v = AT(hfvis_view);
    OK(hfvis_view_orthographic(v, eye_ok, tgt_ok, up_ok, 2.0, 8, 8, 0.1, 10.0));
    BAD('N', INV, hfvis_view_orthographic(NULL, eye_ok, tgt_ok, up_ok, 2.0, 8, 8, 0.1, 10.0));
    BAD('N', INV, hfvis_view_orthographic(v, eye_ok, tgt_ok, NULL, 2.0, 8, 8, 0.1, 10.0));
    BAD('Z', INV, hfvis_view_orthographic(v, eye_ok, tgt_ok, up_ok, 0.0, 8, 8, 0.1, 10.0));
    BAD('G', INV, hfvis_view_orthographic(v, eye_ok, tgt_ok, up_ok, -2.0, 8, 8, 0.1, 10.0));
    BAD('Z', INV, hfvis_view_orthographic(v, eye_ok, tgt_ok, up_ok, 2.0, 8, 0, 0.1, 10.0));
    BAD('F', INV, hfvis_view_orthographic(v, eye_ok, tgt_ok, up_ok, (double)INFINITY, 8, 8, 0.1, 10.0));
    BAD('R', INV, hfvis_view_orthographic(v, eye_ok, tgt_ok, up_ok, 2.0, 8, 8, 10.0, 0.1));
}

static void args_depth_to_eye_z(void)
{
    begin("depth_to_eye_z");
    CHECK(hfvis_depth_to_eye_z(0.0, 0.5, 10.0, 0) == -0.5);
    CHECK(hfvis_depth_to_eye_z(1.0, 0.5, 10.0, 1) == -10.0);
    CHECK(isnan(hfvis_depth_to_eye_z((double)NAN, 0.5, 10.0, 0)));
}

static void args_eye_z_to_depth(void)
{
    begin("eye_z_to_depth");
    CHECK(hfvis_eye_z_to_depth(-0.5, 0.5, 10.0, 0) == 0.0);
    CHECK(isnan(hfvis_eye_z_to_depth((double)NAN, 0.5, 10.0, 1)));
}

static void args_volume_grid_fit(void)
{
    hfvis_volume_grid *g;
    begin("volume_grid_fit");
    g = AT(hfvis_volume_grid);
    OK(hfvis_volume_grid_fit(&m_box, 4, 0.1, 0, g));
    BAD('N', INV, hfvis_volume_grid_fit(NULL, 4, 0.1, 0, g));
    BAD('N', INV, hfvis_volume_grid_fit(&m_box, 4, 0.1, 0, NULL));
    BAD('Z', INV, hfvis_volume_grid_fit(&m_box, 0, 0.1, 0, g));
    BAD('G', INV, hfvis_volume_grid_fit(&m_box, 4, -0.1, 0, g));
    BAD('F', INV, hfvis_volume_grid_fit(&m_box, 4, (double)NAN, 0, g));
    BAD('O', LIM, hfvis_volume_grid_fit(&m_box, 4096, 0.1, 1, g));
    MESH_CASES(hfvis_volume_grid_fit(&bm, 4, 0.1, 0, g), INV);
}

static void args_volume_floats(void)
{
    hfvis_volume_grid b = vg_ok;
    begin("volume_floats");
    CHECK(hfvis_volume_floats(&vg_ok, 2) == 128);
    BADV('N', hfvis_volume_floats(NULL, 2) == 0);
    BADV('Z', hfvis_volume_floats(&vg_ok, 0) == 0);
    BADV('O', hfvis_volume_floats(&vg_ok, HFVIS_VOLUME_MAX_CHANNELS + 1) == 0);
    b.dims[0] = -1;
    BADV('G', hfvis_volume_floats(&b, 1) == 0);
}

static void args_volume_init(void)
{
    hfvis_volume *v;
    float *st;
    begin("volume_init");
    v = AT(hfvis_volume);
    st = AF(64 * 2);
    OK(hfvis_volume_init(v, &vg_ok, 2, st, HFVIS_BLEND_MAX));
    BAD('N', INV, hfvis_volume_init(NULL, &vg_ok, 2, st, HFVIS_BLEND_MAX));
    BAD('N', INV, hfvis_volume_init(v, NULL, 2, st, HFVIS_BLEND_MAX));
    BAD('N', INV, hfvis_volume_init(v, &vg_ok, 2, NULL, HFVIS_BLEND_MAX));
    BAD('Z', INV, hfvis_volume_init(v, &vg_ok, 0, st, HFVIS_BLEND_MAX));
    BAD('O', INV, hfvis_volume_init(v, &vg_ok, 33, st, HFVIS_BLEND_MAX));
    BAD('E', INV, hfvis_volume_init(v, &vg_ok, 2, st, (hfvis_blend)99));
    VGRID_CASES(hfvis_volume_init(v, &bv, 2, st, HFVIS_BLEND_MAX), INV);
}

static void args_volume_clear(void)
{
    hfvis_volume v;
    static float st[64];
    begin("volume_clear");
    CHECK(hfvis_volume_init(&v, &vg_ok, 1, st, HFVIS_BLEND_MAX) == HFVIS_OK);
    hfvis_volume_clear(&v, 2.0f);
    CHECK(st[63] == 2.0f);
    hfvis_volume_clear(NULL, 1.0f);
    v.data = NULL;
    hfvis_volume_clear(&v, 1.0f);
    BADV('N', st[0] == 2.0f);
}

/* A volume over arena storage (so a failing call must leave the storage untouched). */
static hfvis_volume arena_volume(int channels)
{
    hfvis_volume v;
    float *st = AF(64 * channels);
    memset(&v, 0, sizeof v);
    v.grid = vg_ok; v.channels = channels; v.data = st;
    return v;
}

static void args_volume_write(void)
{
    static const float val[2] = {1.0f, 2.0f};
    hfvis_volume v, b;
    begin("volume_write");
    v = arena_volume(2);
    OK(hfvis_volume_write(&v, 1, 2, 3, val));
    BAD('N', INV, hfvis_volume_write(NULL, 1, 2, 3, val));
    BAD('N', INV, hfvis_volume_write(&v, 1, 2, 3, NULL));
    BAD('G', INV, hfvis_volume_write(&v, -1, 2, 3, val));
    BAD('R', INV, hfvis_volume_write(&v, 1, 4, 3, val));
    BAD('O', INV, hfvis_volume_write(&v, 1, 2, INT_MAX, val));
    b = v; b.data = NULL; BAD('N', INV, hfvis_volume_write(&b, 1, 2, 3, val));
    b = v; b.channels = 0; BAD('Z', INV, hfvis_volume_write(&b, 1, 2, 3, val));
    b = v; b.blend[0] = (hfvis_blend)99; BAD('E', INV, hfvis_volume_write(&b, 1, 2, 3, val));
    b = v; b.grid.cell[0] = (double)NAN; BAD('F', INV, hfvis_volume_write(&b, 1, 2, 3, val));
}

static float merge_src[128];

static void args_volume_merge(void)
{
    hfvis_volume d, s, b;
    begin("volume_merge");
    d = arena_volume(2);
    memset(&s, 0, sizeof s);
    s.grid = vg_ok; s.channels = 2; s.data = merge_src;
    OK(hfvis_volume_merge(&d, &s));
    BAD('N', INV, hfvis_volume_merge(NULL, &s));
    BAD('N', INV, hfvis_volume_merge(&d, NULL));
    b = s; b.channels = 1; BAD('R', INV, hfvis_volume_merge(&d, &b));
    b = s; b.grid.dims[2] = 3; BAD('R', INV, hfvis_volume_merge(&d, &b));
    b = s; b.data = NULL; BAD('N', INV, hfvis_volume_merge(&d, &b));
    b = d; b.blend[1] = (hfvis_blend)-1; BAD('E', INV, hfvis_volume_merge(&b, &s));
    b = d; b.channels = 0; BAD('Z', INV, hfvis_volume_merge(&b, &s));
}

/* A generator call that must succeed and is then freed (the output lives in the arena). */
#define GEN_OK(call, meshp) do { arena_fill(); base_status((int)(call), __LINE__); hfvis_mesh_free(NULL, meshp); } while (0)

static const double c_ok[3] = {0, 0, 0};

static void args_mesh_box(void)
{
    static const double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, hn[3] = {1, (double)NAN, 1};
    hfvis_mesh *m;
    begin("mesh_box");
    m = AT(hfvis_mesh);
    GEN_OK(hfvis_mesh_box(NULL, lo, hi, m), m);
    BAD('N', INV, hfvis_mesh_box(NULL, NULL, hi, m));
    BAD('N', INV, hfvis_mesh_box(NULL, lo, NULL, m));
    BAD('N', INV, hfvis_mesh_box(NULL, lo, hi, NULL));
    BAD('R', INV, hfvis_mesh_box(NULL, hi, lo, m));
    BAD('Z', INV, hfvis_mesh_box(NULL, lo, lo, m));
    BAD('F', INV, hfvis_mesh_box(NULL, lo, hn, m));
}

static void args_mesh_uv_sphere(void)
{
    hfvis_mesh *m;
    begin("mesh_uv_sphere");
    m = AT(hfvis_mesh);
    GEN_OK(hfvis_mesh_uv_sphere(NULL, c_ok, 1.0, 4, 3, m), m);
    BAD('N', INV, hfvis_mesh_uv_sphere(NULL, NULL, 1.0, 4, 3, m));
    BAD('N', INV, hfvis_mesh_uv_sphere(NULL, c_ok, 1.0, 4, 3, NULL));
    BAD('Z', INV, hfvis_mesh_uv_sphere(NULL, c_ok, 0.0, 4, 3, m));
    BAD('G', INV, hfvis_mesh_uv_sphere(NULL, c_ok, -1.0, 4, 3, m));
    BAD('F', INV, hfvis_mesh_uv_sphere(NULL, c_ok, (double)NAN, 4, 3, m));
    BAD('F', INV, hfvis_mesh_uv_sphere(NULL, v3_inf, 1.0, 4, 3, m));
    BAD('R', INV, hfvis_mesh_uv_sphere(NULL, c_ok, 1.0, 2, 3, m));
    BAD('R', INV, hfvis_mesh_uv_sphere(NULL, c_ok, 1.0, 4, 1, m));
    BAD('O', LIM, hfvis_mesh_uv_sphere(NULL, c_ok, 1.0, INT_MAX, INT_MAX, m));
    BAD('F', INV, hfvis_mesh_uv_sphere(NULL, c_ok, 1e300, 4, 3, m));
}

static void args_mesh_icosphere(void)
{
    hfvis_mesh *m;
    begin("mesh_icosphere");
    m = AT(hfvis_mesh);
    GEN_OK(hfvis_mesh_icosphere(NULL, c_ok, 1.0, 0, m), m);
    BAD('N', INV, hfvis_mesh_icosphere(NULL, NULL, 1.0, 0, m));
    BAD('N', INV, hfvis_mesh_icosphere(NULL, c_ok, 1.0, 0, NULL));
    BAD('Z', INV, hfvis_mesh_icosphere(NULL, c_ok, 0.0, 0, m));
    BAD('G', INV, hfvis_mesh_icosphere(NULL, c_ok, 1.0, -1, m));
    BAD('F', INV, hfvis_mesh_icosphere(NULL, c_ok, (double)INFINITY, 0, m));
    BAD('O', INV, hfvis_mesh_icosphere(NULL, c_ok, 1.0, HFVIS_MESH_ICOSPHERE_MAX_SUBDIVISIONS + 1, m));
}

static void args_mesh_torus(void)
{
    hfvis_mesh *m;
    begin("mesh_torus");
    m = AT(hfvis_mesh);
    GEN_OK(hfvis_mesh_torus(NULL, c_ok, 2.0, 0.5, 3, 3, m), m);
    BAD('N', INV, hfvis_mesh_torus(NULL, NULL, 2.0, 0.5, 3, 3, m));
    BAD('N', INV, hfvis_mesh_torus(NULL, c_ok, 2.0, 0.5, 3, 3, NULL));
    BAD('Z', INV, hfvis_mesh_torus(NULL, c_ok, 2.0, 0.0, 3, 3, m));
    BAD('R', INV, hfvis_mesh_torus(NULL, c_ok, 0.5, 2.0, 3, 3, m));
    BAD('G', INV, hfvis_mesh_torus(NULL, c_ok, 2.0, 0.5, -3, 3, m));
    BAD('R', INV, hfvis_mesh_torus(NULL, c_ok, 2.0, 0.5, 3, 2, m));
    BAD('F', INV, hfvis_mesh_torus(NULL, c_ok, (double)NAN, 0.5, 3, 3, m));
    BAD('O', LIM, hfvis_mesh_torus(NULL, c_ok, 2.0, 0.5, INT_MAX, INT_MAX, m));
}

static void args_mesh_torus_knot(void)
{
    hfvis_mesh *m;
    begin("mesh_torus_knot");
    m = AT(hfvis_mesh);
    GEN_OK(hfvis_mesh_torus_knot(NULL, c_ok, 1.0, 2, 3, 8, 3, m), m);
    BAD('N', INV, hfvis_mesh_torus_knot(NULL, NULL, 1.0, 2, 3, 8, 3, m));
    BAD('N', INV, hfvis_mesh_torus_knot(NULL, c_ok, 1.0, 2, 3, 8, 3, NULL));
    BAD('Z', INV, hfvis_mesh_torus_knot(NULL, c_ok, 0.0, 2, 3, 8, 3, m));
    BAD('Z', INV, hfvis_mesh_torus_knot(NULL, c_ok, 1.0, 0, 3, 8, 3, m));
    BAD('R', INV, hfvis_mesh_torus_knot(NULL, c_ok, 1.0, 2, 4, 8, 3, m));
    BAD('G', INV, hfvis_mesh_torus_knot(NULL, c_ok, 1.0, 2, 3, -8, 3, m));
    BAD('F', INV, hfvis_mesh_torus_knot(NULL, c_ok, (double)NAN, 2, 3, 8, 3, m));
    BAD('O', LIM, hfvis_mesh_torus_knot(NULL, c_ok, 1.0, 2, 3, INT_MAX, INT_MAX, m));
}

static void args_mesh_from_grid(void)
{
    hfvis_mesh *m;
    hfvis_grid b = g_ok;
    begin("mesh_from_grid");
    m = AT(hfvis_mesh);
    GEN_OK(hfvis_mesh_from_grid(NULL, &g_ok, m), m);
    BAD('N', INV, hfvis_mesh_from_grid(NULL, NULL, m));
    BAD('N', INV, hfvis_mesh_from_grid(NULL, &g_ok, NULL));
    GRID_CASES(hfvis_mesh_from_grid(NULL, &bg, m));
    b.width = 20000; b.height = 20000; b.stride = 20000;
    BAD('O', LIM, hfvis_mesh_from_grid(NULL, &b, m));
    b = g_ok; b.cell_size = 2e38; /* extent 6e38 overflows float */
    BAD('F', INV, hfvis_mesh_from_grid(NULL, &b, m));
}

static void args_mesh_room(void)
{
    hfvis_mesh *m;
    begin("mesh_room");
    m = AT(hfvis_mesh);
    GEN_OK(hfvis_mesh_room(NULL, m), m);
    BAD('N', INV, hfvis_mesh_room(NULL, NULL));
}

static void args_mesh_teapot(void)
{
    hfvis_mesh *m;
    begin("mesh_teapot");
    m = AT(hfvis_mesh);
    GEN_OK(hfvis_mesh_teapot(NULL, 1, m), m);
    BAD('N', INV, hfvis_mesh_teapot(NULL, 1, NULL));
    BAD('Z', INV, hfvis_mesh_teapot(NULL, 0, m));
    BAD('G', INV, hfvis_mesh_teapot(NULL, -1, m));
    BAD('O', LIM, hfvis_mesh_teapot(NULL, 4097, m));
}

static void args_mesh_bounds(void)
{
    double *lo, *hi;
    hfvis_mesh e;
    begin("mesh_bounds");
    lo = AD(3); hi = AD(3);
    OK(hfvis_mesh_bounds(&m_box, lo, hi));
    BAD('N', INV, hfvis_mesh_bounds(NULL, lo, hi));
    BAD('N', INV, hfvis_mesh_bounds(&m_box, NULL, hi));
    BAD('N', INV, hfvis_mesh_bounds(&m_box, lo, NULL));
    memset(&e, 0, sizeof e);
    BAD('Z', INV, hfvis_mesh_bounds(&e, lo, hi));
    MESH_CASES(hfvis_mesh_bounds(&bm, lo, hi), INV);
}

static const char obj_ok[] = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

static void args_obj_decode(void)
{
    static const char bad[] = "v 0 0 0\nf 1 2 9\n", inf[] = "v inf 0 0\n";
    hfvis_mesh *m;
    begin("obj_decode");
    m = AT(hfvis_mesh);
    GEN_OK(hfvis_obj_decode(obj_ok, sizeof obj_ok - 1, NULL, m), m);
    BAD('N', INV, hfvis_obj_decode(NULL, 4, NULL, m));
    BAD('N', INV, hfvis_obj_decode(obj_ok, sizeof obj_ok - 1, NULL, NULL));
    BAD('R', FMT, hfvis_obj_decode(bad, sizeof bad - 1, NULL, m));
    BAD('F', FMT, hfvis_obj_decode(inf, sizeof inf - 1, NULL, m));
    BAD('Z', FMT, hfvis_obj_decode("f 0 1 2\n", 8, NULL, m));
}

static void args_obj_encode_size(void)
{
    hfvis_mesh b = m_box;
    begin("obj_encode_size");
    CHECK(hfvis_obj_encode_size(&m_box) > 0);
    BADV('N', hfvis_obj_encode_size(NULL) == 0);
    b.indices = bad_idx; b.triangle_count = 1;
    BADV('R', hfvis_obj_encode_size(&b) == 0);
    b = m_box; b.triangle_count = SIZE_MAX / 2;
    BADV('O', hfvis_obj_encode_size(&b) == 0);
}

static void args_obj_encode(void)
{
    size_t need = hfvis_obj_encode_size(&m_box), *wr;
    char *out;
    begin("obj_encode");
    out = ATN(char, need);
    wr = AT(size_t);
    OK(hfvis_obj_encode(&m_box, out, need, wr));
    BAD('N', INV, hfvis_obj_encode(NULL, out, need, wr));
    BAD('N', INV, hfvis_obj_encode(&m_box, NULL, need, wr));
    BAD('R', SMALL, hfvis_obj_encode(&m_box, out, need - 1, wr));
    BAD('Z', SMALL, hfvis_obj_encode(&m_box, out, 0, wr));
    MESH_CASES(hfvis_obj_encode(&bm, out, need, wr), INV);
}

static void args_mesh_load(void)
{
    hfvis_mesh *m;
    FILE *f = fopen(tmp_path("a.obj"), "wb");
    if (f) { fputs(obj_ok, f); fclose(f); }
    begin("mesh_load");
    m = AT(hfvis_mesh);
    GEN_OK(hfvis_mesh_load(tmp_path("a.obj"), NULL, m), m);
    BAD('N', INV, hfvis_mesh_load(NULL, NULL, m));
    BAD('N', INV, hfvis_mesh_load(tmp_path("a.obj"), NULL, NULL));
    BAD('R', IOE, hfvis_mesh_load(tmp_path("missing.obj"), NULL, m));
    BAD('R', IOE, hfvis_mesh_load(tmpdir, NULL, m));
}

static void args_mesh_save(void)
{
    begin("mesh_save");
    OK(hfvis_mesh_save(tmp_path("s.obj"), &m_box));
    BAD('N', INV, hfvis_mesh_save(NULL, &m_box));
    BAD('N', INV, hfvis_mesh_save(tmp_path("t.obj"), NULL));
    BAD('R', IOE, hfvis_mesh_save(bad_dir_path("t.obj"), &m_box));
    MESH_CASES(hfvis_mesh_save(tmp_path("t.obj"), &bm), INV);
    BADV('R', access(tmp_path("t.obj"), F_OK) != 0);
}

static void args_raster_options_default(void)
{
    hfvis_raster_options o = hfvis_raster_options_default();
    begin("raster_options_default");
    CHECK(o.cull == HFVIS_CULL_NONE);
}

/* Invalid views, substituted as &bw. */
#define VIEW_CASES(expr) do { hfvis_view bw; \
    bw = view_ok; bw.width = 0; BAD('Z', INV, expr); \
    bw = view_ok; bw.height = -1; BAD('G', INV, expr); \
    bw = view_ok; bw.proj[5] = (double)NAN; BAD('F', INV, expr); \
    bw = view_ok; bw.near_plane = 20.0; BAD('R', INV, expr); \
    bw = view_ok; bw.width = HFVIS_RASTER_MAX_SIZE + 1; BAD('O', LIM, expr); \
    } while (0)
#define RASTER_OPT_CASES(expr) do { hfvis_raster_options bo; \
    bo = hfvis_raster_options_default(); bo.cull = (hfvis_cull_mode)9; BAD('E', INV, expr); \
    bo = hfvis_raster_options_default(); bo.normal_space = (hfvis_normal_space)-1; BAD('E', INV, expr); \
    bo = hfvis_raster_options_default(); bo.normal_toward_viewer = 2; BAD('S', INV, expr); \
    } while (0)

static hfvis_raster_outputs raster_outputs(void)
{
    hfvis_raster_outputs o;
    o.linear_depth = AF(64); o.window_depth = AF(64); o.normal = AF(3 * 64);
    o.triangle_id = ATN(uint32_t, 64); o.barycentric = AF(2 * 64); o.coverage_count = ATN(uint32_t, 64);
    return o;
}

static void args_rasterize(void)
{
    hfvis_raster_outputs o;
    begin("rasterize");
    o = raster_outputs();
    OK(hfvis_rasterize(&m_box, &view_ok, NULL, &o));
    BAD('N', INV, hfvis_rasterize(NULL, &view_ok, NULL, &o));
    BAD('N', INV, hfvis_rasterize(&m_box, NULL, NULL, &o));
    BAD('N', INV, hfvis_rasterize(&m_box, &view_ok, NULL, NULL));
    MESH_CASES(hfvis_rasterize(&bm, &view_ok, NULL, &o), LIM);
    VIEW_CASES(hfvis_rasterize(&m_box, &bw, NULL, &o));
    RASTER_OPT_CASES(hfvis_rasterize(&m_box, &view_ok, &bo, &o));
}

static void args_rasterize_reference(void)
{
    hfvis_raster_outputs o;
    begin("rasterize_reference");
    o = raster_outputs();
    OK(hfvis_rasterize_reference(&m_box, &view_ok, NULL, &o));
    BAD('N', INV, hfvis_rasterize_reference(NULL, &view_ok, NULL, &o));
    BAD('N', INV, hfvis_rasterize_reference(&m_box, NULL, NULL, &o));
    BAD('N', INV, hfvis_rasterize_reference(&m_box, &view_ok, NULL, NULL));
    MESH_CASES(hfvis_rasterize_reference(&bm, &view_ok, NULL, &o), LIM);
    VIEW_CASES(hfvis_rasterize_reference(&m_box, &bw, NULL, &o));
    RASTER_OPT_CASES(hfvis_rasterize_reference(&m_box, &view_ok, &bo, &o));
}

static hfvis_ray ray_ok(void)
{
    hfvis_ray r;
    memset(&r, 0, sizeof r);
    r.origin[0] = 0.5f; r.origin[1] = 0.5f; r.origin[2] = -1.0f;
    r.direction[2] = 1.0f; r.t_max = (double)INFINITY;
    return r;
}

/* Invalid rays, substituted as &br. */
#define RAY_CASES(expr) do { hfvis_ray br; \
    br = ray_ok(); br.direction[2] = 0.0f; BAD('Z', INV, expr); \
    br = ray_ok(); br.origin[0] = (double)NAN; BAD('F', INV, expr); \
    br = ray_ok(); br.direction[1] = (double)INFINITY; BAD('F', INV, expr); \
    br = ray_ok(); br.t_min = -1.0f; BAD('G', INV, expr); \
    br = ray_ok(); br.t_min = 2.0f; br.t_max = 1.0f; BAD('R', INV, expr); \
    br = ray_ok(); br.cull = (hfvis_cull_mode)7; BAD('E', INV, expr); \
    } while (0)

static const float tv0[3] = {0, 0, 0}, tv1[3] = {1, 0, 0}, tv2[3] = {0, 1, 0}, tvn[3] = {0, (double)NAN, 0};

static void args_ray_triangle(void)
{
    hfvis_ray r = ray_ok();
    hfvis_hit *h;
    begin("ray_triangle");
    h = AT(hfvis_hit);
    r.origin[0] = 0.2f; r.origin[1] = 0.2f;
    OK(hfvis_ray_triangle(&r, tv0, tv1, tv2, h));
    BAD('N', INV, hfvis_ray_triangle(NULL, tv0, tv1, tv2, h));
    BAD('N', INV, hfvis_ray_triangle(&r, NULL, tv1, tv2, h));
    BAD('N', INV, hfvis_ray_triangle(&r, tv0, tv1, tv2, NULL));
    BAD('F', INV, hfvis_ray_triangle(&r, tv0, tvn, tv2, h));
    RAY_CASES(hfvis_ray_triangle(&br, tv0, tv1, tv2, h));
}

static void args_bvh_options_default(void)
{
    hfvis_bvh_options o = hfvis_bvh_options_default();
    begin("bvh_options_default");
    CHECK(o.max_leaf_size >= 0);
}

static void args_bvh_build(void)
{
    hfvis_bvh_options o;
    hfvis_bvh *b;
    hfvis_mesh hm = m_box;
    begin("bvh_build");
    b = AT(hfvis_bvh);
    arena_fill();
    base_status(hfvis_bvh_build(&m_box, NULL, b), __LINE__);
    hfvis_bvh_free(NULL, b);
    BAD('N', INV, hfvis_bvh_build(NULL, NULL, b));
    BAD('N', INV, hfvis_bvh_build(&m_box, NULL, NULL));
    o = hfvis_bvh_options_default(); o.max_leaf_size = HFVIS_BVH_MAX_LEAF_SIZE + 1;
    BAD('S', INV, hfvis_bvh_build(&m_box, &o, b));
    o = hfvis_bvh_options_default(); o.max_leaf_size = -1;
    BAD('G', INV, hfvis_bvh_build(&m_box, &o, b));
    o = hfvis_bvh_options_default(); o.bins = 1;
    BAD('S', INV, hfvis_bvh_build(&m_box, &o, b));
    hm.triangle_count = HFVIS_BVH_MAX_TRIANGLES + 1;
    BAD('O', LIM, hfvis_bvh_build(&hm, NULL, b));
    MESH_CASES(hfvis_bvh_build(&bm, NULL, b), LIM);
}

static void args_bvh_free(void)
{
    hfvis_bvh b;
    begin("bvh_free");
    memset(&b, 0, sizeof b);
    hfvis_bvh_free(NULL, NULL);
    hfvis_bvh_free(NULL, &b);
    BADV('N', b.nodes == NULL);
}

/* Invalid BVHs, substituted as &bb. */
#define BVH_CASES(expr) do { hfvis_bvh bb; \
    bb = m_bvh; bb.triangle_count = 3; BAD('R', INV, expr); \
    bb = m_bvh; bb.depth = HFVIS_BVH_MAX_DEPTH + 1; BAD('O', INV, expr); \
    } while (0)

static int accept_all(void *user, const hfvis_ray *r, const hfvis_hit *c)
{
    (void)user; (void)r; (void)c;
    return 1;
}

static void args_bvh_intersect(void)
{
    hfvis_ray r = ray_ok();
    hfvis_hit *h;
    begin("bvh_intersect");
    h = AT(hfvis_hit);
    OK(hfvis_bvh_intersect(&m_bvh, &m_box, &r, HFVIS_RAY_CLOSEST, accept_all, NULL, h));
    BAD('N', INV, hfvis_bvh_intersect(NULL, &m_box, &r, HFVIS_RAY_CLOSEST, NULL, NULL, h));
    BAD('N', INV, hfvis_bvh_intersect(&m_bvh, NULL, &r, HFVIS_RAY_CLOSEST, NULL, NULL, h));
    BAD('N', INV, hfvis_bvh_intersect(&m_bvh, &m_box, NULL, HFVIS_RAY_CLOSEST, NULL, NULL, h));
    BAD('N', INV, hfvis_bvh_intersect(&m_bvh, &m_box, &r, HFVIS_RAY_CLOSEST, NULL, NULL, NULL));
    BAD('E', INV, hfvis_bvh_intersect(&m_bvh, &m_box, &r, (hfvis_ray_query)5, NULL, NULL, h));
    RAY_CASES(hfvis_bvh_intersect(&m_bvh, &m_box, &br, HFVIS_RAY_ANY, NULL, NULL, h));
    BVH_CASES(hfvis_bvh_intersect(&bb, &m_box, &r, HFVIS_RAY_CLOSEST, NULL, NULL, h));
}

static void args_bvh_closest_hit(void)
{
    hfvis_ray r = ray_ok();
    hfvis_hit *h;
    begin("bvh_closest_hit");
    h = AT(hfvis_hit);
    OK(hfvis_bvh_closest_hit(&m_bvh, &m_box, &r, h));
    BAD('N', INV, hfvis_bvh_closest_hit(NULL, &m_box, &r, h));
    BAD('N', INV, hfvis_bvh_closest_hit(&m_bvh, &m_box, &r, NULL));
    RAY_CASES(hfvis_bvh_closest_hit(&m_bvh, &m_box, &br, h));
    BVH_CASES(hfvis_bvh_closest_hit(&bb, &m_box, &r, h));
}

static void args_bvh_any_hit(void)
{
    hfvis_ray r = ray_ok();
    hfvis_hit *h;
    begin("bvh_any_hit");
    h = AT(hfvis_hit);
    OK(hfvis_bvh_any_hit(&m_bvh, &m_box, &r, h));
    BAD('N', INV, hfvis_bvh_any_hit(&m_bvh, NULL, &r, h));
    BAD('N', INV, hfvis_bvh_any_hit(&m_bvh, &m_box, NULL, h));
    RAY_CASES(hfvis_bvh_any_hit(&m_bvh, &m_box, &br, h));
    BVH_CASES(hfvis_bvh_any_hit(&bb, &m_box, &r, h));
}

static void args_ray_intersect_naive(void)
{
    hfvis_ray r = ray_ok();
    hfvis_mesh bm = m_box;
    hfvis_hit *h;
    begin("ray_intersect_naive");
    h = AT(hfvis_hit);
    OK(hfvis_ray_intersect_naive(&m_box, &r, HFVIS_RAY_ANY, accept_all, NULL, h));
    BAD('N', INV, hfvis_ray_intersect_naive(NULL, &r, HFVIS_RAY_ANY, NULL, NULL, h));
    BAD('N', INV, hfvis_ray_intersect_naive(&m_box, NULL, HFVIS_RAY_ANY, NULL, NULL, h));
    BAD('N', INV, hfvis_ray_intersect_naive(&m_box, &r, HFVIS_RAY_ANY, NULL, NULL, NULL));
    BAD('E', INV, hfvis_ray_intersect_naive(&m_box, &r, (hfvis_ray_query)-1, NULL, NULL, h));
    bm.xyz = NULL; BAD('N', INV, hfvis_ray_intersect_naive(&bm, &r, HFVIS_RAY_ANY, NULL, NULL, h));
    bm = m_box; bm.indices = bad_idx; bm.triangle_count = 1;
    BAD('R', INV, hfvis_ray_intersect_naive(&bm, &r, HFVIS_RAY_ANY, NULL, NULL, h));
    RAY_CASES(hfvis_ray_intersect_naive(&m_box, &br, HFVIS_RAY_CLOSEST, NULL, NULL, h));
}

static void args_ray_closest_naive(void)
{
    hfvis_ray r = ray_ok();
    hfvis_hit *h;
    begin("ray_closest_naive");
    h = AT(hfvis_hit);
    OK(hfvis_ray_closest_naive(&m_box, &r, h));
    BAD('N', INV, hfvis_ray_closest_naive(NULL, &r, h));
    BAD('N', INV, hfvis_ray_closest_naive(&m_box, &r, NULL));
    RAY_CASES(hfvis_ray_closest_naive(&m_box, &br, h));
}

static void args_ray_any_naive(void)
{
    hfvis_ray r = ray_ok();
    hfvis_hit *h;
    begin("ray_any_naive");
    h = AT(hfvis_hit);
    OK(hfvis_ray_any_naive(&m_box, &r, h));
    BAD('N', INV, hfvis_ray_any_naive(&m_box, NULL, h));
    BAD('N', INV, hfvis_ray_any_naive(&m_box, &r, NULL));
    RAY_CASES(hfvis_ray_any_naive(&m_box, &br, h));
}

static void args_voxelize_options_default(void)
{
    hfvis_voxelize_options o = hfvis_voxelize_options_default();
    begin("voxelize_options_default");
    CHECK(o.method == HFVIS_VOXELIZE_PIXEL_RULE);
}

static void args_gs_max_slices(void)
{
    begin("gs_max_slices");
    CHECK(hfvis_gs_max_slices(7, 0) == 1 && hfvis_gs_max_slices(6, 1) == 2);
    BADV('Z', hfvis_gs_max_slices(0, 0) == 0);
    BADV('G', hfvis_gs_max_slices(-5, 1) == 0);
    BADV('R', hfvis_gs_max_slices(6, 0) == 0);
}

#define VOXOPT_CASES(expr) do { hfvis_voxelize_options bo; \
    bo = hfvis_voxelize_options_default(); bo.method = (hfvis_voxelize_method)9; BAD('E', INV, expr); \
    bo = hfvis_voxelize_options_default(); bo.axes = (hfvis_voxelize_axes)-1; BAD('E', INV, expr); \
    bo = hfvis_voxelize_options_default(); bo.max_output_vertices = -1; BAD('G', INV, expr); \
    bo = hfvis_voxelize_options_default(); bo.max_output_vertices = 7; BAD('S', INV, expr); \
    bo = hfvis_voxelize_options_default(); bo.method = HFVIS_VOXELIZE_GS_SLICING; \
    bo.max_output_vertices = 6; BAD('S', INV, expr); \
    } while (0)

static void args_voxelize_surface(void)
{
    hfvis_volume v, b;
    size_t *fr;
    begin("voxelize_surface");
    v = arena_volume(1);
    fr = AT(size_t);
    OK(hfvis_voxelize_surface(&m_box, &v, NULL, fr));
    BAD('N', INV, hfvis_voxelize_surface(NULL, &v, NULL, fr));
    BAD('N', INV, hfvis_voxelize_surface(&m_box, NULL, NULL, fr));
    b = v; b.data = NULL; BAD('N', INV, hfvis_voxelize_surface(&m_box, &b, NULL, fr));
    b = v; b.channels = 0; BAD('Z', INV, hfvis_voxelize_surface(&m_box, &b, NULL, fr));
    b = v; b.channels = 33; BAD('O', INV, hfvis_voxelize_surface(&m_box, &b, NULL, fr));
    b = v; b.blend[0] = (hfvis_blend)9; BAD('E', INV, hfvis_voxelize_surface(&m_box, &b, NULL, fr));
    b = v; b.grid.cell[1] = (double)NAN; BAD('F', INV, hfvis_voxelize_surface(&m_box, &b, NULL, fr));
    MESH_CASES(hfvis_voxelize_surface(&bm, &v, NULL, fr), INV);
    VOXOPT_CASES(hfvis_voxelize_surface(&m_box, &v, &bo, fr));
}

static void args_voxelize_surface_reference(void)
{
    hfvis_volume v, b;
    size_t *fr;
    begin("voxelize_surface_reference");
    v = arena_volume(1);
    fr = AT(size_t);
    OK(hfvis_voxelize_surface_reference(&m_box, &v, NULL, fr));
    BAD('N', INV, hfvis_voxelize_surface_reference(NULL, &v, NULL, fr));
    BAD('N', INV, hfvis_voxelize_surface_reference(&m_box, NULL, NULL, fr));
    b = v; b.channels = 0; BAD('Z', INV, hfvis_voxelize_surface_reference(&m_box, &b, NULL, fr));
    b = v; b.blend[0] = (hfvis_blend)9; BAD('E', INV, hfvis_voxelize_surface_reference(&m_box, &b, NULL, fr));
    b = v; b.grid.origin[0] = (double)INFINITY; BAD('F', INV, hfvis_voxelize_surface_reference(&m_box, &b, NULL, fr));
    MESH_CASES(hfvis_voxelize_surface_reference(&bm, &v, NULL, fr), INV);
    VOXOPT_CASES(hfvis_voxelize_surface_reference(&m_box, &v, &bo, fr));
}

static void args_voxelize_occupancy(void)
{
    uint8_t *occ;
    begin("voxelize_occupancy");
    occ = ATN(uint8_t, 64);
    OK(hfvis_voxelize_occupancy(&m_box, &vg_ok, NULL, occ));
    BAD('N', INV, hfvis_voxelize_occupancy(NULL, &vg_ok, NULL, occ));
    BAD('N', INV, hfvis_voxelize_occupancy(&m_box, NULL, NULL, occ));
    BAD('N', INV, hfvis_voxelize_occupancy(&m_box, &vg_ok, NULL, NULL));
    MESH_CASES(hfvis_voxelize_occupancy(&bm, &vg_ok, NULL, occ), INV);
    VGRID_CASES(hfvis_voxelize_occupancy(&m_box, &bv, NULL, occ), INV);
    VOXOPT_CASES(hfvis_voxelize_occupancy(&m_box, &vg_ok, &bo, occ));
}

static hfvis_voxel_fragment frag_ok(void)
{
    hfvis_voxel_fragment f;
    memset(&f, 0, sizeof f);
    f.normal[2] = 1.0f; f.barycentric[0] = 1.0f;
    return f;
}

static void args_voxel_fragment_occupancy(void)
{
    hfvis_voxel_fragment f = frag_ok();
    float v[HFVIS_VOLUME_MAX_CHANNELS] = {0};
    begin("voxel_fragment_occupancy");
    hfvis_voxel_fragment_occupancy(&f, v, NULL);
    hfvis_voxel_fragment_occupancy(NULL, v, NULL); /* f and user unused */
    CHECK(v[0] == 1.0f);
}

static void args_voxel_fragment_normal_occupancy(void)
{
    hfvis_voxel_fragment f = frag_ok();
    float v[HFVIS_VOLUME_MAX_CHANNELS] = {0};
    begin("voxel_fragment_normal_occupancy");
    hfvis_voxel_fragment_normal_occupancy(&f, v, NULL);
    CHECK(v[0] == 1.0f && v[3] == 1.0f);
}

static void args_voxel_attribute_channel(void)
{
    begin("voxel_attribute_channel");
    CHECK(hfvis_voxel_attribute_channel(HFVIS_VOXEL_ATTR_OCCUPANCY | HFVIS_VOXEL_ATTR_NORMAL, HFVIS_VOXEL_ATTR_NORMAL) == 1);
    BADV('R', hfvis_voxel_attribute_channel(HFVIS_VOXEL_ATTR_OCCUPANCY, HFVIS_VOXEL_ATTR_ALBEDO) == -1);
    BADV('E', hfvis_voxel_attribute_channel(HFVIS_VOXEL_ATTR_OCCUPANCY, 0x40u) == -1);
}

static void args_voxel_fragment_attributes(void)
{
    hfvis_voxel_fragment f = frag_ok();
    hfvis_voxel_attributes at;
    float v[HFVIS_VOLUME_MAX_CHANNELS] = {0};
    begin("voxel_fragment_attributes");
    memset(&at, 0, sizeof at);
    at.flags = HFVIS_VOXEL_ATTR_OCCUPANCY | HFVIS_VOXEL_ATTR_ALBEDO | 0x1000u;
    hfvis_voxel_fragment_attributes(&f, v, &at);
    CHECK(v[0] == 1.0f && v[1] == 1.0f);
    memset(v, 0, sizeof v);
    hfvis_voxel_fragment_attributes(&f, v, NULL);
    BADV('N', v[0] == 1.0f && v[1] == 0.0f);
}

static void args_binary_voxel_options_default(void)
{
    hfvis_binary_voxel_options o = hfvis_binary_voxel_options_default();
    begin("binary_voxel_options_default");
    CHECK(o.alloc == NULL);
}

static void args_triangle_box_overlap(void)
{
    static const double c[3] = {0.5, 0.5, 0.5}, h[3] = {0.5, 0.5, 0.5};
    static const double a[3] = {0, 0, 0.5}, b[3] = {1, 0, 0.5}, d[3] = {0, 1, 0.5};
    begin("triangle_box_overlap");
    CHECK(hfvis_triangle_box_overlap(c, h, a, b, d) == 1);
    CHECK(hfvis_triangle_box_overlap(c, h, a, a, a) == 1); /* degenerate: a point */
}

#define BINOPT_CASES(expr) do { hfvis_binary_voxel_options bo; \
    bo = hfvis_binary_voxel_options_default(); bo.axis = (hfvis_parity_axis)9; BAD('E', INV, expr); \
    } while (0)

static void args_voxelize_conservative(void)
{
    uint8_t *occ;
    size_t *cnt;
    begin("voxelize_conservative");
    occ = ATN(uint8_t, 64); cnt = AT(size_t);
    OK(hfvis_voxelize_conservative(&m_box, &vg_ok, NULL, occ, cnt));
    BAD('N', INV, hfvis_voxelize_conservative(NULL, &vg_ok, NULL, occ, cnt));
    BAD('N', INV, hfvis_voxelize_conservative(&m_box, NULL, NULL, occ, cnt));
    BAD('N', INV, hfvis_voxelize_conservative(&m_box, &vg_ok, NULL, NULL, cnt));
    MESH_CASES(hfvis_voxelize_conservative(&bm, &vg_ok, NULL, occ, cnt), INV);
    VGRID_CASES(hfvis_voxelize_conservative(&m_box, &bv, NULL, occ, cnt), INV);
}

static void args_voxelize_conservative_reference(void)
{
    uint8_t *occ;
    size_t *cnt;
    begin("voxelize_conservative_reference");
    occ = ATN(uint8_t, 64); cnt = AT(size_t);
    OK(hfvis_voxelize_conservative_reference(&m_box, &vg_ok, NULL, occ, cnt));
    BAD('N', INV, hfvis_voxelize_conservative_reference(NULL, &vg_ok, NULL, occ, cnt));
    BAD('N', INV, hfvis_voxelize_conservative_reference(&m_box, NULL, NULL, occ, cnt));
    BAD('N', INV, hfvis_voxelize_conservative_reference(&m_box, &vg_ok, NULL, NULL, cnt));
    MESH_CASES(hfvis_voxelize_conservative_reference(&bm, &vg_ok, NULL, occ, cnt), INV);
    VGRID_CASES(hfvis_voxelize_conservative_reference(&m_box, &bv, NULL, occ, cnt), INV);
}

static void args_voxelize_solid(void)
{
    uint8_t *occ;
    size_t *cnt;
    hfvis_mesh open = m_box;
    begin("voxelize_solid");
    occ = ATN(uint8_t, 64); cnt = AT(size_t);
    OK(hfvis_voxelize_solid(&m_box, &vg_ok, NULL, occ, cnt));
    BAD('N', INV, hfvis_voxelize_solid(NULL, &vg_ok, NULL, occ, cnt));
    BAD('N', INV, hfvis_voxelize_solid(&m_box, NULL, NULL, occ, cnt));
    BAD('N', INV, hfvis_voxelize_solid(&m_box, &vg_ok, NULL, NULL, cnt));
    open.triangle_count = 11;
    BAD('R', FMT, hfvis_voxelize_solid(&open, &vg_ok, NULL, occ, cnt));
    MESH_CASES(hfvis_voxelize_solid(&bm, &vg_ok, NULL, occ, cnt), INV);
    VGRID_CASES(hfvis_voxelize_solid(&m_box, &bv, NULL, occ, cnt), INV);
    BINOPT_CASES(hfvis_voxelize_solid(&m_box, &vg_ok, &bo, occ, cnt));
}

static void args_voxelize_solid_reference(void)
{
    uint8_t *occ;
    size_t *cnt;
    begin("voxelize_solid_reference");
    occ = ATN(uint8_t, 64); cnt = AT(size_t);
    OK(hfvis_voxelize_solid_reference(&m_box, &vg_ok, NULL, occ, cnt));
    BAD('N', INV, hfvis_voxelize_solid_reference(NULL, &vg_ok, NULL, occ, cnt));
    BAD('N', INV, hfvis_voxelize_solid_reference(&m_box, NULL, NULL, occ, cnt));
    BAD('N', INV, hfvis_voxelize_solid_reference(&m_box, &vg_ok, NULL, NULL, cnt));
    MESH_CASES(hfvis_voxelize_solid_reference(&bm, &vg_ok, NULL, occ, cnt), INV);
    VGRID_CASES(hfvis_voxelize_solid_reference(&m_box, &bv, NULL, occ, cnt), INV);
    BINOPT_CASES(hfvis_voxelize_solid_reference(&m_box, &vg_ok, &bo, occ, cnt));
}

static void args_mesh_is_watertight(void)
{
    int *r;
    begin("mesh_is_watertight");
    r = AT(int);
    OK(hfvis_mesh_is_watertight(&m_box, NULL, r));
    BAD('N', INV, hfvis_mesh_is_watertight(NULL, NULL, r));
    BAD('N', INV, hfvis_mesh_is_watertight(&m_box, NULL, NULL));
    MESH_CASES(hfvis_mesh_is_watertight(&bm, NULL, r), INV);
}

static void args_bitmask_words(void)
{
    hfvis_volume_grid b = vg_ok;
    begin("bitmask_words");
    CHECK(hfvis_bitmask_words(&vg_ok) == 16);
    BADV('N', hfvis_bitmask_words(NULL) == 0);
    b.dims[2] = 0;
    BADV('Z', hfvis_bitmask_words(&b) == 0);
    b = vg_ok; b.cell[0] = (double)NAN;
    BADV('F', hfvis_bitmask_words(&b) == 0);
}

static void args_voxelize_bitmask(void)
{
    uint32_t *bits;
    size_t *cnt;
    begin("voxelize_bitmask");
    bits = ATN(uint32_t, 16); cnt = AT(size_t);
    OK(hfvis_voxelize_bitmask(&m_box, &vg_ok, NULL, bits, cnt));
    BAD('N', INV, hfvis_voxelize_bitmask(NULL, &vg_ok, NULL, bits, cnt));
    BAD('N', INV, hfvis_voxelize_bitmask(&m_box, NULL, NULL, bits, cnt));
    BAD('N', INV, hfvis_voxelize_bitmask(&m_box, &vg_ok, NULL, NULL, cnt));
    MESH_CASES(hfvis_voxelize_bitmask(&bm, &vg_ok, NULL, bits, cnt), INV);
    VGRID_CASES(hfvis_voxelize_bitmask(&m_box, &bv, NULL, bits, cnt), INV);
}

static void args_bitmask_to_occupancy(void)
{
    static uint32_t bits[16];
    uint8_t *occ;
    begin("bitmask_to_occupancy");
    occ = ATN(uint8_t, 64);
    OK(hfvis_bitmask_to_occupancy(&vg_ok, bits, occ));
    BAD('N', INV, hfvis_bitmask_to_occupancy(NULL, bits, occ));
    BAD('N', INV, hfvis_bitmask_to_occupancy(&vg_ok, NULL, occ));
    BAD('N', INV, hfvis_bitmask_to_occupancy(&vg_ok, bits, NULL));
    VGRID_CASES(hfvis_bitmask_to_occupancy(&bv, bits, occ), INV);
}

static void args_binvox_encode_size(void)
{
    hfvis_volume_grid b = vg_ok;
    begin("binvox_encode_size");
    CHECK(hfvis_binvox_encode_size(&vg_ok, occ_box) > 0);
    BADV('N', hfvis_binvox_encode_size(NULL, occ_box) == 0);
    BADV('N', hfvis_binvox_encode_size(&vg_ok, NULL) == 0);
    b.dims[0] = 0;
    BADV('Z', hfvis_binvox_encode_size(&b, occ_box) == 0);
    b = vg_ok; b.cell[0] = 1e308;
    BADV('O', hfvis_binvox_encode_size(&b, occ_box) == 0);
}

static void args_binvox_encode(void)
{
    size_t need = hfvis_binvox_encode_size(&vg_ok, occ_box), *wr;
    hfvis_volume_grid b = vg_ok;
    char *out;
    begin("binvox_encode");
    out = ATN(char, need); wr = AT(size_t);
    OK(hfvis_binvox_encode(&vg_ok, occ_box, out, need, wr));
    BAD('N', INV, hfvis_binvox_encode(NULL, occ_box, out, need, wr));
    BAD('N', INV, hfvis_binvox_encode(&vg_ok, NULL, out, need, wr));
    BAD('N', INV, hfvis_binvox_encode(&vg_ok, occ_box, NULL, need, wr));
    BAD('N', INV, hfvis_binvox_encode(&vg_ok, occ_box, out, need, NULL));
    BAD('R', SMALL, hfvis_binvox_encode(&vg_ok, occ_box, out, need - 1, wr));
    BAD('Z', SMALL, hfvis_binvox_encode(&vg_ok, occ_box, out, 0, wr));
    b.dims[0] = 2048; b.dims[1] = 1; b.dims[2] = 1;
    BAD('O', LIM, hfvis_binvox_encode(&b, occ_box, out, need, wr));
    b = vg_ok; b.cell[0] = 1e308;
    BAD('O', LIM, hfvis_binvox_encode(&b, occ_box, out, need, wr));
    b = vg_ok; b.cell[1] = (double)NAN;
    BAD('F', INV, hfvis_binvox_encode(&b, occ_box, out, need, wr));
    b = vg_ok; b.dims[2] = -1;
    BAD('G', INV, hfvis_binvox_encode(&b, occ_box, out, need, wr));
}

static char binvox_buf[1024];
static size_t binvox_len;

static void args_binvox_decode(void)
{
    static const char bad[] = "#binvox 1\ndim 2 2 3\ndata\n";
    static const char huge[] = "#binvox 1\ndim 4096 4096 4096\ndata\n";
    hfvis_volume_grid *g;
    uint8_t **occ;
    begin("binvox_decode");
    CHECK(hfvis_binvox_encode(&vg_ok, occ_box, binvox_buf, sizeof binvox_buf, &binvox_len) == HFVIS_OK);
    g = AT(hfvis_volume_grid); occ = AT(uint8_t *);
    arena_fill();
    base_status(hfvis_binvox_decode(binvox_buf, binvox_len, NULL, g, occ), __LINE__);
    hfvis_free(NULL, *occ);
    BAD('N', INV, hfvis_binvox_decode(NULL, binvox_len, NULL, g, occ));
    BAD('N', INV, hfvis_binvox_decode(binvox_buf, binvox_len, NULL, NULL, occ));
    BAD('N', INV, hfvis_binvox_decode(binvox_buf, binvox_len, NULL, g, NULL));
    BAD('Z', FMT, hfvis_binvox_decode(binvox_buf, 0, NULL, g, occ));
    BAD('R', FMT, hfvis_binvox_decode(bad, sizeof bad - 1, NULL, g, occ));
    BAD('O', LIM, hfvis_binvox_decode(huge, sizeof huge - 1, NULL, g, occ));
}

static void args_binvox_save(void)
{
    hfvis_volume_grid b = vg_ok;
    begin("binvox_save");
    OK(hfvis_binvox_save(tmp_path("s.binvox"), &vg_ok, occ_box));
    BAD('N', INV, hfvis_binvox_save(NULL, &vg_ok, occ_box));
    BAD('N', INV, hfvis_binvox_save(tmp_path("t.binvox"), NULL, occ_box));
    BAD('N', INV, hfvis_binvox_save(tmp_path("t.binvox"), &vg_ok, NULL));
    BAD('R', IOE, hfvis_binvox_save(bad_dir_path("t.binvox"), &vg_ok, occ_box));
    b.dims[0] = 0;
    BAD('Z', INV, hfvis_binvox_save(tmp_path("t.binvox"), &b, occ_box));
    BADV('R', access(tmp_path("t.binvox"), F_OK) != 0);
}

static void args_binvox_load(void)
{
    hfvis_volume_grid *g;
    uint8_t **occ;
    begin("binvox_load");
    g = AT(hfvis_volume_grid); occ = AT(uint8_t *);
    arena_fill();
    base_status(hfvis_binvox_load(tmp_path("s.binvox"), NULL, g, occ), __LINE__);
    hfvis_free(NULL, *occ);
    BAD('N', INV, hfvis_binvox_load(NULL, NULL, g, occ));
    BAD('N', INV, hfvis_binvox_load(tmp_path("s.binvox"), NULL, NULL, occ));
    BAD('N', INV, hfvis_binvox_load(tmp_path("s.binvox"), NULL, g, NULL));
    BAD('R', IOE, hfvis_binvox_load(tmp_path("missing.binvox"), NULL, g, occ));
}

static void args_voxels_raw_save(void)
{
    begin("voxels_raw_save");
    OK(hfvis_voxels_raw_save(tmp_path("s.raw"), &vg_ok, occ_box));
    BAD('N', INV, hfvis_voxels_raw_save(NULL, &vg_ok, occ_box));
    BAD('N', INV, hfvis_voxels_raw_save(tmp_path("t.raw"), NULL, occ_box));
    BAD('N', INV, hfvis_voxels_raw_save(tmp_path("t.raw"), &vg_ok, NULL));
    BAD('R', IOE, hfvis_voxels_raw_save(bad_dir_path("t.raw"), &vg_ok, occ_box));
    VGRID_CASES(hfvis_voxels_raw_save(tmp_path("t.raw"), &bv, occ_box), INV);
    BADV('R', access(tmp_path("t.raw"), F_OK) != 0);
}

/* ---- incremental voxelization --------------------------------------------------------------- */

static float iv_depth[64];
static hfvis_depth_image iv_img;

static void make_depth_image(void)
{
    hfvis_raster_outputs o;
    memset(&o, 0, sizeof o);
    o.window_depth = iv_depth;
    if (hfvis_rasterize(&m_box, &view_ok, NULL, &o) != HFVIS_OK) exit(2);
    memset(&iv_img, 0, sizeof iv_img);
    iv_img.view = view_ok; iv_img.depth = iv_depth;
}

/* Invalid depth images, substituted as &bi (one image). */
#define IMAGE_CASES(expr) do { hfvis_depth_image bi; \
    bi = iv_img; bi.depth = NULL; BAD('N', INV, expr); \
    bi = iv_img; bi.view.width = 0; BAD('Z', INV, expr); \
    bi = iv_img; bi.view.view[3] = (double)NAN; BAD('F', INV, expr); \
    bi = iv_img; bi.view.near_plane = -1.0; BAD('G', INV, expr); \
    bi = iv_img; bi.attribute_count = HFVIS_VOLUME_MAX_CHANNELS + 1; BAD('O', INV, expr); \
    } while (0)
#define IVOPT_CASES(expr) do { hfvis_iv_options bo; \
    bo = hfvis_iv_options_default(); bo.bias_rule = (hfvis_iv_bias_rule)9; BAD('E', INV, expr); \
    bo = hfvis_iv_options_default(); bo.footprint = (hfvis_iv_footprint)-1; BAD('E', INV, expr); \
    bo = hfvis_iv_options_default(); bo.bias_rule = HFVIS_IV_BIAS_EXPLICIT; bo.bias = (double)NAN; BAD('F', INV, expr); \
    bo = hfvis_iv_options_default(); bo.bias_rule = HFVIS_IV_BIAS_EXPLICIT; bo.bias = -1.0; BAD('S', INV, expr); \
    } while (0)

static void args_iv_options_default(void)
{
    hfvis_iv_options o = hfvis_iv_options_default();
    begin("iv_options_default");
    CHECK(o.occupancy_channel == 0);
}

static void args_iv_bias_half_diagonal(void)
{
    hfvis_volume_grid b = vg_ok;
    begin("iv_bias_half_diagonal");
    CHECK(hfvis_iv_bias_half_diagonal(&vg_ok) > 0.0);
    BADV('N', isnan(hfvis_iv_bias_half_diagonal(NULL)));
    b.cell[0] = (double)NAN;
    BADV('F', isnan(hfvis_iv_bias_half_diagonal(&b)));
    b = vg_ok; b.dims[0] = 0;
    BADV('Z', isnan(hfvis_iv_bias_half_diagonal(&b)));
}

static void args_iv_bias(void)
{
    double *o;
    begin("iv_bias");
    o = AD(1);
    OK(hfvis_iv_bias(&vg_ok, NULL, o));
    BAD('N', INV, hfvis_iv_bias(NULL, NULL, o));
    BAD('N', INV, hfvis_iv_bias(&vg_ok, NULL, NULL));
    VGRID_CASES(hfvis_iv_bias(&bv, NULL, o), INV);
    {   /* only the bias rule and bias are read */
        hfvis_iv_options bo = hfvis_iv_options_default();
        bo.bias_rule = (hfvis_iv_bias_rule)9; BAD('E', INV, hfvis_iv_bias(&vg_ok, &bo, o));
        bo.bias_rule = HFVIS_IV_BIAS_EXPLICIT; bo.bias = (double)NAN; BAD('F', INV, hfvis_iv_bias(&vg_ok, &bo, o));
        bo.bias = -1.0; BAD('S', INV, hfvis_iv_bias(&vg_ok, &bo, o));
    }
}

static void args_iv_classify(void)
{
    static const double p[3] = {0.5, 0.5, 0.5};
    hfvis_iv_sample *s;
    begin("iv_classify");
    s = AT(hfvis_iv_sample);
    OK(hfvis_iv_classify(&iv_img, p, 0.1, s));
    BAD('N', INV, hfvis_iv_classify(NULL, p, 0.1, s));
    BAD('N', INV, hfvis_iv_classify(&iv_img, NULL, 0.1, s));
    BAD('N', INV, hfvis_iv_classify(&iv_img, p, 0.1, NULL));
    BAD('F', INV, hfvis_iv_classify(&iv_img, v3_nan, 0.1, s));
    BAD('F', INV, hfvis_iv_classify(&iv_img, p, (double)NAN, s));
    BAD('G', INV, hfvis_iv_classify(&iv_img, p, -0.1, s));
    IMAGE_CASES(hfvis_iv_classify(&bi, p, 0.1, s));
}

static void args_iv_classify_voxel(void)
{
    hfvis_iv_sample *s;
    begin("iv_classify_voxel");
    s = AT(hfvis_iv_sample);
    OK(hfvis_iv_classify_voxel(&iv_img, &vg_ok, 1, 2, 3, NULL, s));
    BAD('N', INV, hfvis_iv_classify_voxel(NULL, &vg_ok, 1, 2, 3, NULL, s));
    BAD('N', INV, hfvis_iv_classify_voxel(&iv_img, NULL, 1, 2, 3, NULL, s));
    BAD('N', INV, hfvis_iv_classify_voxel(&iv_img, &vg_ok, 1, 2, 3, NULL, NULL));
    BAD('G', INV, hfvis_iv_classify_voxel(&iv_img, &vg_ok, -1, 2, 3, NULL, s));
    BAD('R', INV, hfvis_iv_classify_voxel(&iv_img, &vg_ok, 1, 4, 3, NULL, s));
    IMAGE_CASES(hfvis_iv_classify_voxel(&bi, &vg_ok, 1, 2, 3, NULL, s));
    VGRID_CASES(hfvis_iv_classify_voxel(&iv_img, &bv, 1, 2, 3, NULL, s), INV);
    IVOPT_CASES(hfvis_iv_classify_voxel(&iv_img, &vg_ok, 1, 2, 3, &bo, s));
}

static float iv_prev_data[64 * 2];

static hfvis_volume iv_prev(void)
{
    hfvis_volume v;
    int i;
    memset(&v, 0, sizeof v);
    v.grid = vg_ok; v.channels = 2; v.data = iv_prev_data;
    for (i = 0; i < 128; i++) iv_prev_data[i] = (i % 3 == 0) ? 1.0f : 0.0f;
    return v;
}

/* The shared cases of cleanup / update / single pass: fn(prev, curr, images, count, opts, stats). */
#define IV_PASS_CASES(fn) do { hfvis_volume bp; \
    BAD('N', INV, fn(NULL, &cur, &iv_img, 1, NULL, st)); \
    BAD('N', INV, fn(&prev, NULL, &iv_img, 1, NULL, st)); \
    BAD('N', INV, fn(&prev, &cur, NULL, 1, NULL, st)); \
    BAD('O', INV, fn(&prev, &cur, &iv_img, SIZE_MAX / 2, NULL, st)); \
    bp = cur; bp.data = NULL; BAD('N', INV, fn(&prev, &bp, &iv_img, 1, NULL, st)); \
    bp = cur; bp.channels = 1; BAD('R', INV, fn(&prev, &bp, &iv_img, 1, NULL, st)); \
    bp = cur; bp.grid.dims[0] = 3; BAD('R', INV, fn(&prev, &bp, &iv_img, 1, NULL, st)); \
    bp = cur; bp.channels = 0; BAD('Z', INV, fn(&prev, &bp, &iv_img, 1, NULL, st)); \
    IMAGE_CASES(fn(&prev, &cur, &bi, 1, NULL, st)); \
    IVOPT_CASES(fn(&prev, &cur, &iv_img, 1, &bo, st)); \
    two_images[0] = iv_img; two_images[1] = iv_img; two_images[1].depth = NULL; \
    BAD('N', INV, fn(&prev, &cur, two_images, 2, NULL, st)); \
    two_images[1] = iv_img; two_images[1].view.far_plane = (double)NAN; \
    BAD('F', INV, fn(&prev, &cur, two_images, 2, NULL, st)); \
    } while (0)
/* An image pair whose second image is invalid: nothing may be written for the first. */
static hfvis_depth_image two_images[2];

static void args_iv_cleanup(void)
{
    hfvis_volume prev = iv_prev(), cur;
    hfvis_iv_stats *st;
    begin("iv_cleanup");
    cur = arena_volume(2);
    st = AT(hfvis_iv_stats);
    OK(hfvis_iv_cleanup(&prev, &cur, &iv_img, 1, NULL, st));
    OK(hfvis_iv_cleanup(&prev, &cur, NULL, 0, NULL, NULL));
    IV_PASS_CASES(hfvis_iv_cleanup);
}

static void args_iv_inject(void)
{
    hfvis_volume cur, b;
    hfvis_iv_stats *st;
    hfvis_iv_options o;
    begin("iv_inject");
    cur = arena_volume(2);
    st = AT(hfvis_iv_stats);
    OK(hfvis_iv_inject(&cur, &iv_img, 1, NULL, st));
    BAD('N', INV, hfvis_iv_inject(NULL, &iv_img, 1, NULL, st));
    BAD('N', INV, hfvis_iv_inject(&cur, NULL, 1, NULL, st));
    b = cur; b.data = NULL; BAD('N', INV, hfvis_iv_inject(&b, &iv_img, 1, NULL, st));
    o = hfvis_iv_options_default(); o.grid_width = -1;
    BAD('G', INV, hfvis_iv_inject(&cur, &iv_img, 1, &o, st));
    o = hfvis_iv_options_default(); o.occupancy_channel = 2;
    BAD('R', INV, hfvis_iv_inject(&cur, &iv_img, 1, &o, st));
    IMAGE_CASES(hfvis_iv_inject(&cur, &bi, 1, NULL, st));
    two_images[0] = iv_img; two_images[1] = iv_img; two_images[1].view.width = 0;
    BAD('Z', INV, hfvis_iv_inject(&cur, two_images, 2, NULL, st));
    two_images[1] = iv_img; two_images[1].attribute_count = 1; /* attributes NULL */
    BAD('N', INV, hfvis_iv_inject(&cur, two_images, 2, NULL, st));
    IVOPT_CASES(hfvis_iv_inject(&cur, &iv_img, 1, &bo, st));
}

static void args_iv_update(void)
{
    hfvis_volume prev = iv_prev(), cur;
    hfvis_iv_stats *st;
    begin("iv_update");
    cur = arena_volume(2);
    st = AT(hfvis_iv_stats);
    OK(hfvis_iv_update(&prev, &cur, &iv_img, 1, NULL, st));
    IV_PASS_CASES(hfvis_iv_update);
}

static void args_iv_single_pass(void)
{
    hfvis_volume prev = iv_prev(), cur;
    hfvis_iv_stats *st;
    begin("iv_single_pass");
    cur = arena_volume(2);
    st = AT(hfvis_iv_stats);
    OK(hfvis_iv_single_pass(&prev, &cur, &iv_img, 1, NULL, st));
    IV_PASS_CASES(hfvis_iv_single_pass);
}

static void args_iv_replace_nonempty(void)
{
    static const int ch_ok[1] = {1}, ch_dup[2] = {1, 1}, ch_bad[1] = {5};
    hfvis_volume cur, inj = iv_prev(), b;
    size_t *rep;
    begin("iv_replace_nonempty");
    cur = arena_volume(2);
    rep = AT(size_t);
    OK(hfvis_iv_replace_nonempty(&cur, &inj, ch_ok, 1, NULL, rep));
    OK(hfvis_iv_replace_nonempty(&cur, &inj, NULL, 0, NULL, NULL));
    BAD('N', INV, hfvis_iv_replace_nonempty(NULL, &inj, ch_ok, 1, NULL, rep));
    BAD('N', INV, hfvis_iv_replace_nonempty(&cur, NULL, ch_ok, 1, NULL, rep));
    BAD('R', INV, hfvis_iv_replace_nonempty(&cur, &inj, ch_dup, 2, NULL, rep));
    BAD('R', INV, hfvis_iv_replace_nonempty(&cur, &inj, ch_bad, 1, NULL, rep));
    BAD('Z', INV, hfvis_iv_replace_nonempty(&cur, &inj, ch_ok, 0, NULL, rep));
    BAD('O', INV, hfvis_iv_replace_nonempty(&cur, &inj, ch_ok, 3, NULL, rep));
    b = inj; b.channels = 1; BAD('R', INV, hfvis_iv_replace_nonempty(&cur, &b, ch_ok, 1, NULL, rep));
    {   /* only the occupancy channel of opts is read */
        hfvis_iv_options bo = hfvis_iv_options_default();
        bo.occupancy_channel = 2; BAD('S', INV, hfvis_iv_replace_nonempty(&cur, &inj, ch_ok, 1, &bo, rep));
        bo.occupancy_channel = -7; BAD('G', INV, hfvis_iv_replace_nonempty(&cur, &inj, ch_ok, 1, &bo, rep));
    }
}

static void args_iv_occupancy(void)
{
    hfvis_volume v = iv_prev(), b;
    uint8_t *o;
    size_t *cnt;
    begin("iv_occupancy");
    o = ATN(uint8_t, 64); cnt = AT(size_t);
    OK(hfvis_iv_occupancy(&v, 0, o, cnt));
    OK(hfvis_iv_occupancy(&v, HFVIS_IV_NO_CHANNEL, o, NULL));
    BAD('N', INV, hfvis_iv_occupancy(NULL, 0, o, cnt));
    BAD('N', INV, hfvis_iv_occupancy(&v, 0, NULL, cnt));
    BAD('R', INV, hfvis_iv_occupancy(&v, 2, o, cnt));
    BAD('G', INV, hfvis_iv_occupancy(&v, -2, o, cnt));
    b = v; b.data = NULL; BAD('N', INV, hfvis_iv_occupancy(&b, 0, o, cnt));
    b = v; b.grid.dims[0] = 0; BAD('Z', INV, hfvis_iv_occupancy(&b, 0, o, cnt));
}

static void args_point_triangle_distance(void)
{
    static const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0, 1, 0}, p[3] = {0, 0, 2};
    begin("point_triangle_distance");
    CHECK(hfvis_point_triangle_distance(p, a, b, c) == 2.0);
    BADV('N', isnan(hfvis_point_triangle_distance(NULL, a, b, c)));
    BADV('N', isnan(hfvis_point_triangle_distance(p, a, b, NULL)));
}

#define DIST_CASES(fn) do { hfvis_distance_options bo; static const uint8_t empty[64]; \
    BAD('N', INV, fn(NULL, &vg_ok, occ_box, &o, out)); \
    BAD('N', INV, fn(&m_box, NULL, occ_box, &o, out)); \
    BAD('N', INV, fn(&m_box, &vg_ok, NULL, &o, out)); \
    BAD('N', INV, fn(&m_box, &vg_ok, occ_box, &o, NULL)); \
    BAD('Z', INV, fn(&m_box, &vg_ok, empty, &o, out)); \
    MESH_CASES(fn(&bm, &vg_ok, occ_box, &o, out), INV); \
    VGRID_CASES(fn(&m_box, &bv, occ_box, &o, out), INV); \
    (void)bo; \
    } while (0)

static void args_voxel_distance_metrics(void)
{
    hfvis_distance_options o;
    hfvis_distance_metrics *out;
    begin("voxel_distance_metrics");
    memset(&o, 0, sizeof o);
    o.sample_count = 64;
    out = AT(hfvis_distance_metrics);
    OK(hfvis_voxel_distance_metrics(&m_box, &vg_ok, occ_box, &o, out));
    DIST_CASES(hfvis_voxel_distance_metrics);
}

static void args_voxel_distance_metrics_naive(void)
{
    hfvis_distance_options o;
    hfvis_distance_metrics *out;
    begin("voxel_distance_metrics_naive");
    memset(&o, 0, sizeof o);
    o.sample_count = 64;
    out = AT(hfvis_distance_metrics);
    OK(hfvis_voxel_distance_metrics_naive(&m_box, &vg_ok, occ_box, &o, out));
    DIST_CASES(hfvis_voxel_distance_metrics_naive);
}

/* ---- visibility fields ------------------------------------------------------------------------ */

/* Invalid fields, substituted as &bf. */
#define VF_CASES(expr) do { hfvis_visfield bf; \
    bf = vf_ok; bf.maps = NULL; BAD('N', INV, expr); \
    bf = vf_ok; bf.radius = 0.0; BAD('Z', INV, expr); \
    bf = vf_ok; bf.radius = -1.0; BAD('G', INV, expr); \
    bf = vf_ok; bf.center[1] = (double)NAN; BAD('F', INV, expr); \
    bf = vf_ok; bf.format = (hfvis_visfield_format)9; BAD('E', INV, expr); \
    bf = vf_ok; bf.mapping = (hfvis_dirmap)-1; BAD('E', INV, expr); \
    bf = vf_ok; bf.positions_n = HFVIS_VISFIELD_MAX_N + 1; BAD('O', INV, expr); \
    bf = vf_ok; bf.maps_size = 1; BAD('R', INV, expr); \
    bf = vf_ok; bf.avg_distance = 2.0; BAD('S', INV, expr); \
    } while (0)

static void args_visfield_position_count(void)
{
    begin("visfield_position_count");
    CHECK(hfvis_visfield_position_count(1) == 10);
    BADV('Z', hfvis_visfield_position_count(0) == 0);
    BADV('G', hfvis_visfield_position_count(-1) == 0);
    BADV('O', hfvis_visfield_position_count(HFVIS_VISFIELD_MAX_N + 1) == 0);
}

static void args_visfield_position(void)
{
    double *d;
    begin("visfield_position");
    d = AD(3);
    OK(hfvis_visfield_position(1, 3, d));
    BAD('N', INV, hfvis_visfield_position(1, 3, NULL));
    BAD('Z', INV, hfvis_visfield_position(0, 3, d));
    BAD('O', INV, hfvis_visfield_position(HFVIS_VISFIELD_MAX_N + 1, 3, d));
    BAD('R', INV, hfvis_visfield_position(1, 10, d));
}

static void args_visfield_nearest_position(void)
{
    size_t *k;
    begin("visfield_nearest_position");
    k = AT(size_t);
    OK(hfvis_visfield_nearest_position(2, v3_ok, k));
    BAD('N', INV, hfvis_visfield_nearest_position(2, NULL, k));
    BAD('N', INV, hfvis_visfield_nearest_position(2, v3_ok, NULL));
    BAD('Z', INV, hfvis_visfield_nearest_position(2, v3_zero, k));
    BAD('F', INV, hfvis_visfield_nearest_position(2, v3_nan, k));
    BAD('G', INV, hfvis_visfield_nearest_position(-2, v3_ok, k));
    BAD('O', INV, hfvis_visfield_nearest_position(HFVIS_VISFIELD_MAX_N + 1, v3_ok, k));
}

static void args_visfield_nearest_position_naive(void)
{
    size_t *k;
    begin("visfield_nearest_position_naive");
    k = AT(size_t);
    OK(hfvis_visfield_nearest_position_naive(2, v3_ok, k));
    BAD('N', INV, hfvis_visfield_nearest_position_naive(2, NULL, k));
    BAD('N', INV, hfvis_visfield_nearest_position_naive(2, v3_ok, NULL));
    BAD('Z', INV, hfvis_visfield_nearest_position_naive(2, v3_zero, k));
    BAD('F', INV, hfvis_visfield_nearest_position_naive(2, v3_inf, k));
    BAD('G', INV, hfvis_visfield_nearest_position_naive(-2, v3_ok, k));
    BAD('O', INV, hfvis_visfield_nearest_position_naive(HFVIS_VISFIELD_MAX_N + 1, v3_ok, k));
}

static void args_visfield_frame(void)
{
    static const double w[3] = {0, 0, -1};
    double t[3], b[3];
    begin("visfield_frame");
    hfvis_visfield_frame(w, t, b);
    CHECK(fabs(t[0] * b[0] + t[1] * b[1] + t[2] * b[2]) < UNIT_VECTOR_TOL);
}

static void args_concentric_square_to_disk(void)
{
    double x, y;
    begin("concentric_square_to_disk");
    hfvis_concentric_square_to_disk(0.0, 0.0, &x, &y);
    CHECK(x == 0.0 && y == 0.0);
    hfvis_concentric_square_to_disk(1.0, 1.0, &x, &y);
    CHECK(fabs(x * x + y * y - 1.0) < UNIT_VECTOR_TOL);
}

static void args_concentric_disk_to_square(void)
{
    double a, b;
    begin("concentric_disk_to_square");
    hfvis_concentric_disk_to_square(0.0, 0.0, &a, &b);
    CHECK(a == 0.0 && b == 0.0);
}

static void args_dirmap_to_local(void)
{
    double *l;
    int *used;
    begin("dirmap_to_local");
    l = AD(3); used = AT(int);
    OK(hfvis_dirmap_to_local(HFVIS_DIRMAP_CONCENTRIC, 4, 1, 2, l, used));
    BAD('N', INV, hfvis_dirmap_to_local(HFVIS_DIRMAP_CONCENTRIC, 4, 1, 2, NULL, used));
    BAD('N', INV, hfvis_dirmap_to_local(HFVIS_DIRMAP_CONCENTRIC, 4, 1, 2, l, NULL));
    BAD('E', INV, hfvis_dirmap_to_local((hfvis_dirmap)9, 4, 1, 2, l, used));
    BAD('Z', INV, hfvis_dirmap_to_local(HFVIS_DIRMAP_CONCENTRIC, 0, 0, 0, l, used));
    BAD('O', INV, hfvis_dirmap_to_local(HFVIS_DIRMAP_CONCENTRIC, HFVIS_VISFIELD_MAX_DIR_RES + 1, 1, 2, l, used));
    BAD('G', INV, hfvis_dirmap_to_local(HFVIS_DIRMAP_CONCENTRIC, 4, -1, 2, l, used));
    BAD('R', INV, hfvis_dirmap_to_local(HFVIS_DIRMAP_CONCENTRIC, 4, 1, 4, l, used));
}

static void args_dirmap_from_local(void)
{
    static const double l[3] = {0.1, 0.2, 0.9}, ldown[3] = {0.1, 0.2, -0.9};
    int *i, *j, *used;
    begin("dirmap_from_local");
    i = AT(int); j = AT(int); used = AT(int);
    OK(hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, 4, l, i, j, used));
    OK(hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, 4, l, i, j, NULL));
    BAD('N', INV, hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, 4, NULL, i, j, used));
    BAD('N', INV, hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, 4, l, NULL, j, used));
    BAD('N', INV, hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, 4, l, i, NULL, used));
    BAD('E', INV, hfvis_dirmap_from_local((hfvis_dirmap)99, 4, l, i, j, used));
    BAD('Z', INV, hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, 0, l, i, j, used));
    BAD('Z', INV, hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, 4, v3_zero, i, j, used));
    BAD('F', INV, hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, 4, v3_nan, i, j, used));
    BAD('R', INV, hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, 4, ldown, i, j, used));
    BAD('O', INV, hfvis_dirmap_from_local(HFVIS_DIRMAP_POLAR, HFVIS_VISFIELD_MAX_DIR_RES + 1, l, i, j, used));
}

static void args_visfield_size(void)
{
    begin("visfield_size");
    CHECK(hfvis_visfield_size(1, 2, HFVIS_VISFIELD_U8) == 40);
    BADV('Z', hfvis_visfield_size(0, 2, HFVIS_VISFIELD_U8) == 0);
    BADV('G', hfvis_visfield_size(1, -2, HFVIS_VISFIELD_U8) == 0);
    BADV('O', hfvis_visfield_size(1, HFVIS_VISFIELD_MAX_DIR_RES + 1, HFVIS_VISFIELD_U8) == 0);
    BADV('E', hfvis_visfield_size(1, 2, (hfvis_visfield_format)9) == 0);
}

static void args_visfield_bounding_sphere(void)
{
    double *c, *r;
    hfvis_mesh e;
    begin("visfield_bounding_sphere");
    c = AD(3); r = AD(1);
    OK(hfvis_visfield_bounding_sphere(&m_box, c, r));
    BAD('N', INV, hfvis_visfield_bounding_sphere(NULL, c, r));
    BAD('N', INV, hfvis_visfield_bounding_sphere(&m_box, NULL, r));
    BAD('N', INV, hfvis_visfield_bounding_sphere(&m_box, c, NULL));
    memset(&e, 0, sizeof e);
    BAD('Z', INV, hfvis_visfield_bounding_sphere(&e, c, r));
    MESH_CASES(hfvis_visfield_bounding_sphere(&bm, c, r), INV);
}

/* A field over arena maps (so that a failing build must leave them untouched). */
static hfvis_visfield arena_field(void)
{
    hfvis_visfield v = vf_ok;
    v.maps = out_bytes(hfvis_visfield_size(1, 2, HFVIS_VISFIELD_U8));
    v.maps_size = hfvis_visfield_size(1, 2, HFVIS_VISFIELD_U8);
    return v;
}

#define VF_BUILD_CASES(fn, vfp) do { hfvis_visfield bf; hfvis_visfield_build_options bo; \
    BAD('N', INV, fn(NULL, NULL, vfp)); \
    BAD('N', INV, fn(&m_box, NULL, NULL)); \
    bf = *(vfp); bf.maps = NULL; BAD('N', INV, fn(&m_box, NULL, &bf)); \
    bf = *(vfp); bf.radius = 0.0; BAD('Z', INV, fn(&m_box, NULL, &bf)); \
    bf = *(vfp); bf.radius = 0.1; BAD('R', INV, fn(&m_box, NULL, &bf)); \
    bf = *(vfp); bf.center[0] = (double)INFINITY; BAD('F', INV, fn(&m_box, NULL, &bf)); \
    bf = *(vfp); bf.format = (hfvis_visfield_format)9; BAD('E', INV, fn(&m_box, NULL, &bf)); \
    bf = *(vfp); bf.dir_res = HFVIS_VISFIELD_MAX_DIR_RES + 1; BAD('O', INV, fn(&m_box, NULL, &bf)); \
    bf = *(vfp); bf.maps_size -= 1; BAD('R', SMALL, fn(&m_box, NULL, &bf)); \
    (void)bo; \
    MESH_CASES(fn(&bm, NULL, vfp), INV); \
    CHECK(memcmp(vfp, &tmpl, sizeof tmpl) == 0); \
    } while (0)

static void args_visfield_build(void)
{
    hfvis_visfield vs, tmpl, *v = &vs; /* parameters in; maps (arena) and avg_distance out */
    begin("visfield_build");
    vs = arena_field();
    tmpl = vs;
    bad_bvh = m_bvh; bad_bvh.triangle_count = 3;
    OK(hfvis_visfield_build(&m_box, NULL, v));
    tmpl = vs;
    {   /* a caller BVH of another mesh (the oracle ignores opts->bvh) */
        hfvis_visfield_build_options bo;
        memset(&bo, 0, sizeof bo);
        bo.bvh = &bad_bvh;
        BAD('S', INV, hfvis_visfield_build(&m_box, &bo, v));
    }
    VF_BUILD_CASES(hfvis_visfield_build, v);
}

static void args_visfield_build_reference(void)
{
    hfvis_visfield vs, tmpl, *v = &vs; /* parameters in; maps (arena) and avg_distance out */
    begin("visfield_build_reference");
    vs = arena_field();
    tmpl = vs;
    OK(hfvis_visfield_build_reference(&m_box, NULL, v));
    tmpl = vs;
    VF_BUILD_CASES(hfvis_visfield_build_reference, v);
}

static void args_visfield_texel(void)
{
    int *hit;
    double *d, *n;
    begin("visfield_texel");
    hit = AT(int); d = AD(1); n = AD(3);
    OK(hfvis_visfield_texel(&vf_ok, 3, 1, 1, hit, d, n));
    OK(hfvis_visfield_texel(&vf_ok, 3, 1, 1, hit, d, NULL));
    BAD('N', INV, hfvis_visfield_texel(NULL, 3, 1, 1, hit, d, n));
    BAD('N', INV, hfvis_visfield_texel(&vf_ok, 3, 1, 1, NULL, d, n));
    BAD('N', INV, hfvis_visfield_texel(&vf_ok, 3, 1, 1, hit, NULL, n));
    BAD('R', INV, hfvis_visfield_texel(&vf_ok, 10, 1, 1, hit, d, n));
    BAD('G', INV, hfvis_visfield_texel(&vf_ok, 3, -1, 1, hit, d, n));
    BAD('R', INV, hfvis_visfield_texel(&vf_ok, 3, 1, 2, hit, d, n));
    VF_CASES(hfvis_visfield_texel(&bf, 3, 1, 1, hit, d, n));
}

static const double q_o[3] = {3.0, 0.5, 0.5}, q_d[3] = {-1.0, 0.0, 0.0};

static void args_visfield_query(void)
{
    hfvis_visfield_hit *h;
    begin("visfield_query");
    h = AT(hfvis_visfield_hit);
    OK(hfvis_visfield_query(&vf_ok, q_o, q_d, 0.01, h));
    BAD('N', INV, hfvis_visfield_query(NULL, q_o, q_d, 0.01, h));
    BAD('N', INV, hfvis_visfield_query(&vf_ok, NULL, q_d, 0.01, h));
    BAD('N', INV, hfvis_visfield_query(&vf_ok, q_o, NULL, 0.01, h));
    BAD('N', INV, hfvis_visfield_query(&vf_ok, q_o, q_d, 0.01, NULL));
    BAD('Z', INV, hfvis_visfield_query(&vf_ok, q_o, v3_zero, 0.01, h));
    BAD('F', INV, hfvis_visfield_query(&vf_ok, v3_nan, q_d, 0.01, h));
    BAD('F', INV, hfvis_visfield_query(&vf_ok, q_o, q_d, (double)INFINITY, h));
    BAD('G', INV, hfvis_visfield_query(&vf_ok, q_o, q_d, -0.01, h));
    VF_CASES(hfvis_visfield_query(&bf, q_o, q_d, 0.01, h));
}

static void args_visfield_query_reference(void)
{
    hfvis_visfield_hit *h;
    hfvis_visfield nm = vf_ok;
    begin("visfield_query_reference");
    h = AT(hfvis_visfield_hit);
    nm.maps = NULL;
    OK(hfvis_visfield_query_reference(&vf_ok, &m_box, &m_bvh, q_o, q_d, 0.01, h));
    OK(hfvis_visfield_query_reference(&nm, &m_box, NULL, q_o, q_d, 0.01, h));
    BAD('N', INV, hfvis_visfield_query_reference(NULL, &m_box, &m_bvh, q_o, q_d, 0.01, h));
    BAD('N', INV, hfvis_visfield_query_reference(&vf_ok, NULL, &m_bvh, q_o, q_d, 0.01, h));
    BAD('N', INV, hfvis_visfield_query_reference(&vf_ok, &m_box, &m_bvh, NULL, q_d, 0.01, h));
    BAD('N', INV, hfvis_visfield_query_reference(&vf_ok, &m_box, &m_bvh, q_o, q_d, 0.01, NULL));
    BAD('Z', INV, hfvis_visfield_query_reference(&vf_ok, &m_box, &m_bvh, q_o, v3_zero, 0.01, h));
    BAD('F', INV, hfvis_visfield_query_reference(&vf_ok, &m_box, &m_bvh, q_o, q_d, (double)NAN, h));
    BAD('G', INV, hfvis_visfield_query_reference(&vf_ok, &m_box, &m_bvh, q_o, q_d, -1.0, h));
    BAD('R', INV, hfvis_visfield_query_reference(&vf_ok, &m_box, &bad_bvh, q_o, q_d, 0.01, h));
    nm.radius = -1.0;
    BAD('S', INV, hfvis_visfield_query_reference(&nm, &m_box, NULL, q_o, q_d, 0.01, h));
}

static void args_visfield_ao_options_default(void)
{
    hfvis_visfield_ao_options o = hfvis_visfield_ao_options_default();
    begin("visfield_ao_options_default");
    CHECK(o.rays_sqrt >= 0);
}

/* Invalid scene objects, substituted as &bo1 (one object). */
#define VFOBJ_CASES(expr) do { hfvis_visfield_object bo1; hfvis_visfield bfl; \
    bo1 = vf_obj; bo1.field = NULL; BAD('N', INV, expr); \
    bo1 = vf_obj; bo1.object_to_world[0] = (double)NAN; BAD('F', INV, expr); \
    bo1 = vf_obj; bo1.object_to_world[0] = 2.0; BAD('S', INV, expr); \
    bo1 = vf_obj; bo1.object_to_world[3] = 1.0; BAD('S', INV, expr); \
    bo1 = vf_obj; bfl = vf_ok; bfl.format = (hfvis_visfield_format)9; bo1.field = &bfl; BAD('E', INV, expr); \
    } while (0)

static const float vp_pts[3] = {0.5f, 0.5f, 1.5f}, vp_nrm[3] = {0.0f, 0.0f, -1.0f}, vp_zero[3] = {0, 0, 0};
static const float vp_nan[3] = {0.5f, (double)NAN, 1.5f};

/* Second point / normal / object invalid: the first one's output must not be written. */
static const float vp_pts2[6] = {0.5f, 0.5f, 1.5f, 0.5f, 0.5f, 1.6f};
static const float vp_pts2_nan[6] = {0.5f, 0.5f, 1.5f, 0.5f, (double)NAN, 1.6f};
static const float vp_nrm2[6] = {0, 0, -1, 0, 0, -1}, vp_nrm2_zero[6] = {0, 0, -1, 0, 0, 0};
static hfvis_visfield_object objs2[2];

#define VFAO_CASES(fn) do { hfvis_visfield_ao_options bq; float *out2 = AF(2); \
    BAD('N', INV, fn(NULL, 1, vp_pts, vp_nrm, 1, NULL, out)); \
    BAD('N', INV, fn(&vf_obj, 1, NULL, vp_nrm, 1, NULL, out)); \
    BAD('N', INV, fn(&vf_obj, 1, vp_pts, NULL, 1, NULL, out)); \
    BAD('N', INV, fn(&vf_obj, 1, vp_pts, vp_nrm, 1, NULL, NULL)); \
    BAD('Z', INV, fn(&vf_obj, 1, vp_pts, vp_zero, 1, NULL, out)); \
    BAD('F', INV, fn(&vf_obj, 1, vp_nan, vp_nrm, 1, NULL, out)); \
    BAD('O', INV, fn(&vf_obj, 1, vp_pts, vp_nrm, SIZE_MAX / 2, NULL, out)); \
    BAD('O', INV, fn(&vf_obj, SIZE_MAX / 2, vp_pts, vp_nrm, 1, NULL, out)); \
    VFOBJ_CASES(fn(&bo1, 1, vp_pts, vp_nrm, 1, NULL, out)); \
    bq = hfvis_visfield_ao_options_default(); bq.rays_sqrt = HFVIS_VISFIELD_MAX_RAYS_SQRT + 1; BAD('O', INV, fn(&vf_obj, 1, vp_pts, vp_nrm, 1, &bq, out)); \
    bq = hfvis_visfield_ao_options_default(); bq.rays_sqrt = -1; BAD('G', INV, fn(&vf_obj, 1, vp_pts, vp_nrm, 1, &bq, out)); \
    bq = hfvis_visfield_ao_options_default(); bq.max_distance = (double)NAN; BAD('F', INV, fn(&vf_obj, 1, vp_pts, vp_nrm, 1, &bq, out)); \
    bq = hfvis_visfield_ao_options_default(); bq.falloff = (hfvis_visfield_falloff)9; BAD('E', INV, fn(&vf_obj, 1, vp_pts, vp_nrm, 1, &bq, out)); \
    bq = hfvis_visfield_ao_options_default(); bq.combine = (hfvis_visfield_combine)-1; BAD('E', INV, fn(&vf_obj, 1, vp_pts, vp_nrm, 1, &bq, out)); \
    bq = hfvis_visfield_ao_options_default(); bq.falloff = HFVIS_VISFIELD_FALLOFF_LINEAR; BAD('S', INV, fn(&vf_obj, 1, vp_pts, vp_nrm, 1, &bq, out)); \
    bq = hfvis_visfield_ao_options_default(); bq.offset = -1.0; BAD('S', INV, fn(&vf_obj, 1, vp_pts, vp_nrm, 1, &bq, out)); \
    bq = hfvis_visfield_ao_options_default(); bq.bias = -0.1; BAD('S', INV, fn(&vf_obj, 1, vp_pts, vp_nrm, 1, &bq, out)); \
    bq = hfvis_visfield_ao_options_default(); bq.max_distance = -1.0; BAD('S', INV, fn(&vf_obj, 1, vp_pts, vp_nrm, 1, &bq, out)); \
    BAD('F', INV, fn(&vf_obj, 1, vp_pts2_nan, vp_nrm2, 2, NULL, out2)); \
    BAD('Z', INV, fn(&vf_obj, 1, vp_pts2, vp_nrm2_zero, 2, NULL, out2)); \
    objs2[0] = vf_obj; objs2[1] = vf_obj; objs2[1].object_to_world[5] = 3.0; \
    BAD('S', INV, fn(objs2, 2, vp_pts2, vp_nrm2, 2, NULL, out2)); \
    } while (0)

static void args_visfield_ambient_occlusion(void)
{
    hfvis_visfield_ao_options o = hfvis_visfield_ao_options_default();
    float *out;
    begin("visfield_ambient_occlusion");
    o.rays_sqrt = 2;
    out = AF(1);
    OK(hfvis_visfield_ambient_occlusion(&vf_obj, 1, vp_pts, vp_nrm, 1, &o, out));
    VFAO_CASES(hfvis_visfield_ambient_occlusion);
}

static void args_visfield_ambient_occlusion_reference(void)
{
    hfvis_visfield_ao_options o = hfvis_visfield_ao_options_default();
    hfvis_visfield_object bm_obj = vf_obj;
    float *out;
    begin("visfield_ambient_occlusion_reference");
    o.rays_sqrt = 2;
    out = AF(1);
    OK(hfvis_visfield_ambient_occlusion_reference(&vf_obj, 1, vp_pts, vp_nrm, 1, &o, out));
    VFAO_CASES(hfvis_visfield_ambient_occlusion_reference);
    bm_obj.mesh = NULL;
    BAD('N', INV, hfvis_visfield_ambient_occlusion_reference(&bm_obj, 1, vp_pts, vp_nrm, 1, &o, out));
    bm_obj = vf_obj; bm_obj.bvh = &bad_bvh;
    BAD('R', INV, hfvis_visfield_ambient_occlusion_reference(&bm_obj, 1, vp_pts, vp_nrm, 1, &o, out));
}

static const double light_c[3] = {0.5, 0.5, 4.0};

#define VFSHADOW_CASES(fn) do { hfvis_visfield_shadow_options bq; float *out2 = AF(2); \
    BAD('N', INV, fn(NULL, 1, vp_pts, 1, light_c, 0.5, NULL, out)); \
    BAD('N', INV, fn(&vf_obj, 1, NULL, 1, light_c, 0.5, NULL, out)); \
    BAD('N', INV, fn(&vf_obj, 1, vp_pts, 1, NULL, 0.5, NULL, out)); \
    BAD('N', INV, fn(&vf_obj, 1, vp_pts, 1, light_c, 0.5, NULL, NULL)); \
    BAD('F', INV, fn(&vf_obj, 1, vp_nan, 1, light_c, 0.5, NULL, out)); \
    BAD('O', INV, fn(&vf_obj, 1, vp_pts, SIZE_MAX / 2, light_c, 0.5, NULL, out)); \
    BAD('F', INV, fn(&vf_obj, 1, vp_pts, 1, v3_nan, 0.5, NULL, out)); \
    BAD('F', INV, fn(&vf_obj, 1, vp_pts, 1, light_c, (double)INFINITY, NULL, out)); \
    BAD('G', INV, fn(&vf_obj, 1, vp_pts, 1, light_c, -0.5, NULL, out)); \
    VFOBJ_CASES(fn(&bo1, 1, vp_pts, 1, light_c, 0.5, NULL, out)); \
    memset(&bq, 0, sizeof bq); bq.samples = HFVIS_VISFIELD_MAX_SAMPLES + 1; BAD('O', INV, fn(&vf_obj, 1, vp_pts, 1, light_c, 0.5, &bq, out)); \
    memset(&bq, 0, sizeof bq); bq.samples = -1; BAD('G', INV, fn(&vf_obj, 1, vp_pts, 1, light_c, 0.5, &bq, out)); \
    memset(&bq, 0, sizeof bq); bq.bias = (double)NAN; BAD('S', INV, fn(&vf_obj, 1, vp_pts, 1, light_c, 0.5, &bq, out)); \
    BAD('F', INV, fn(&vf_obj, 1, vp_pts2_nan, 2, light_c, 0.5, NULL, out2)); \
    objs2[0] = vf_obj; objs2[1] = vf_obj; objs2[1].field = NULL; \
    BAD('N', INV, fn(objs2, 2, vp_pts2, 2, light_c, 0.5, NULL, out2)); \
    } while (0)

static void args_visfield_soft_shadow(void)
{
    hfvis_visfield_shadow_options o;
    float *out;
    begin("visfield_soft_shadow");
    memset(&o, 0, sizeof o);
    o.samples = 4;
    out = AF(1);
    OK(hfvis_visfield_soft_shadow(&vf_obj, 1, vp_pts, 1, light_c, 0.5, &o, out));
    VFSHADOW_CASES(hfvis_visfield_soft_shadow);
}

static void args_visfield_soft_shadow_reference(void)
{
    hfvis_visfield_shadow_options o;
    float *out;
    begin("visfield_soft_shadow_reference");
    memset(&o, 0, sizeof o);
    o.samples = 4;
    out = AF(1);
    OK(hfvis_visfield_soft_shadow_reference(&vf_obj, 1, vp_pts, 1, light_c, 0.5, &o, out));
    VFSHADOW_CASES(hfvis_visfield_soft_shadow_reference);
}

#define VFTRACE_CASES(fn) do { \
    BAD('N', INV, fn(NULL, 1, q_o, q_d, 0.0, h)); \
    BAD('N', INV, fn(&vf_obj, 1, NULL, q_d, 0.0, h)); \
    BAD('N', INV, fn(&vf_obj, 1, q_o, NULL, 0.0, h)); \
    BAD('N', INV, fn(&vf_obj, 1, q_o, q_d, 0.0, NULL)); \
    BAD('Z', INV, fn(&vf_obj, 1, q_o, v3_zero, 0.0, h)); \
    BAD('O', INV, fn(&vf_obj, SIZE_MAX / 2, q_o, q_d, 0.0, h)); \
    BAD('F', INV, fn(&vf_obj, 1, v3_inf, q_d, 0.0, h)); \
    BAD('F', INV, fn(&vf_obj, 1, q_o, q_d, (double)NAN, h)); \
    BAD('G', INV, fn(&vf_obj, 1, q_o, q_d, -0.1, h)); \
    VFOBJ_CASES(fn(&bo1, 1, q_o, q_d, 0.0, h)); \
    objs2[0] = vf_obj; objs2[1] = vf_obj; objs2[1].object_to_world[12] = (double)INFINITY; \
    BAD('F', INV, fn(objs2, 2, q_o, q_d, 0.0, h)); \
    } while (0)

static void args_visfield_trace(void)
{
    hfvis_visfield_trace_hit *h;
    begin("visfield_trace");
    h = AT(hfvis_visfield_trace_hit);
    OK(hfvis_visfield_trace(&vf_obj, 1, q_o, q_d, 0.0, h));
    VFTRACE_CASES(hfvis_visfield_trace);
}

static void args_visfield_trace_reference(void)
{
    hfvis_visfield_trace_hit *h;
    begin("visfield_trace_reference");
    h = AT(hfvis_visfield_trace_hit);
    OK(hfvis_visfield_trace_reference(&vf_obj, 1, q_o, q_d, 0.0, h));
    VFTRACE_CASES(hfvis_visfield_trace_reference);
}

#define VFREFL_CASES(fn) do { hfvis_visfield_reflect_options bq; \
    BAD('N', INV, fn(NULL, 1, rp, rn, ri, NULL, h)); \
    BAD('N', INV, fn(&vf_obj, 1, NULL, rn, ri, NULL, h)); \
    BAD('N', INV, fn(&vf_obj, 1, rp, NULL, ri, NULL, h)); \
    BAD('N', INV, fn(&vf_obj, 1, rp, rn, NULL, NULL, h)); \
    BAD('N', INV, fn(&vf_obj, 1, rp, rn, ri, NULL, NULL)); \
    BAD('Z', INV, fn(&vf_obj, 1, rp, v3_zero, ri, NULL, h)); \
    BAD('Z', INV, fn(&vf_obj, 1, rp, rn, v3_zero, NULL, h)); \
    BAD('F', INV, fn(&vf_obj, 1, v3_nan, rn, ri, NULL, h)); \
    VFOBJ_CASES(fn(&bo1, 1, rp, rn, ri, NULL, h)); \
    memset(&bq, 0, sizeof bq); bq.rays = HFVIS_VISFIELD_MAX_SAMPLES + 1; BAD('O', INV, fn(&vf_obj, 1, rp, rn, ri, &bq, h)); \
    memset(&bq, 0, sizeof bq); bq.rays = -1; BAD('G', INV, fn(&vf_obj, 1, rp, rn, ri, &bq, h)); \
    memset(&bq, 0, sizeof bq); bq.shininess = -1.0; BAD('S', INV, fn(&vf_obj, 1, rp, rn, ri, &bq, h)); \
    memset(&bq, 0, sizeof bq); bq.offset = (double)NAN; BAD('S', INV, fn(&vf_obj, 1, rp, rn, ri, &bq, h)); \
    } while (0)

static const double rp[3] = {0.5, 0.5, 3.0}, rn[3] = {0, 0, 1}, ri[3] = {0.3, 0, -1};

static void args_visfield_reflect(void)
{
    hfvis_visfield_trace_hit *h;
    begin("visfield_reflect");
    h = ATN(hfvis_visfield_trace_hit, 4);
    OK(hfvis_visfield_reflect(&vf_obj, 1, rp, rn, ri, NULL, h));
    VFREFL_CASES(hfvis_visfield_reflect);
}

static void args_visfield_reflect_reference(void)
{
    hfvis_visfield_trace_hit *h;
    begin("visfield_reflect_reference");
    h = ATN(hfvis_visfield_trace_hit, 4);
    OK(hfvis_visfield_reflect_reference(&vf_obj, 1, rp, rn, ri, NULL, h));
    VFREFL_CASES(hfvis_visfield_reflect_reference);
}

static void args_visfield_encode_size(void)
{
    hfvis_visfield b = vf_ok;
    begin("visfield_encode_size");
    CHECK(hfvis_visfield_encode_size(&vf_ok) == HFVIS_VISFIELD_FILE_HEADER + 40);
    BADV('N', hfvis_visfield_encode_size(NULL) == 0);
    b.dir_res = 0;
    BADV('Z', hfvis_visfield_encode_size(&b) == 0);
    b = vf_ok; b.format = (hfvis_visfield_format)9;
    BADV('E', hfvis_visfield_encode_size(&b) == 0);
}

static void args_visfield_encode(void)
{
    size_t need = hfvis_visfield_encode_size(&vf_ok), *wr;
    unsigned char *out;
    begin("visfield_encode");
    out = ATN(unsigned char, need); wr = AT(size_t);
    OK(hfvis_visfield_encode(&vf_ok, out, need, wr));
    OK(hfvis_visfield_encode(&vf_ok, out, need, NULL));
    BAD('N', INV, hfvis_visfield_encode(NULL, out, need, wr));
    BAD('N', INV, hfvis_visfield_encode(&vf_ok, NULL, need, wr));
    BAD('R', SMALL, hfvis_visfield_encode(&vf_ok, out, need - 1, wr));
    VF_CASES(hfvis_visfield_encode(&bf, out, need, wr));
}

static unsigned char vf_file[256];
static size_t vf_file_len;

static void args_visfield_decode(void)
{
    hfvis_visfield *v;
    unsigned char bad[256];
    begin("visfield_decode");
    CHECK(hfvis_visfield_encode(&vf_ok, vf_file, sizeof vf_file, &vf_file_len) == HFVIS_OK);
    v = AT(hfvis_visfield);
    arena_fill();
    base_status(hfvis_visfield_decode(vf_file, vf_file_len, NULL, v), __LINE__);
    hfvis_visfield_free(NULL, v);
    BAD('N', INV, hfvis_visfield_decode(NULL, vf_file_len, NULL, v));
    BAD('N', INV, hfvis_visfield_decode(vf_file, vf_file_len, NULL, NULL));
    BAD('Z', FMT, hfvis_visfield_decode(vf_file, 0, NULL, v));
    BAD('R', FMT, hfvis_visfield_decode(vf_file, vf_file_len - 1, NULL, v));
    memcpy(bad, vf_file, vf_file_len);
    bad[20] = 0xFF; bad[21] = 0xFF; /* positions_n 65535 > HFVIS_VISFIELD_MAX_N */
    BAD('O', LIM, hfvis_visfield_decode(bad, vf_file_len, NULL, v));
    memcpy(bad, vf_file, vf_file_len);
    memset(bad + 56, 0xFF, 8); /* radius NaN */
    BAD('F', FMT, hfvis_visfield_decode(bad, vf_file_len, NULL, v));
    memcpy(bad, vf_file, vf_file_len);
    bad[12] = 9; /* format */
    BAD('E', FMT, hfvis_visfield_decode(bad, vf_file_len, NULL, v));
}

static void args_visfield_free(void)
{
    hfvis_visfield v;
    begin("visfield_free");
    memset(&v, 0, sizeof v);
    hfvis_visfield_free(NULL, NULL);
    hfvis_visfield_free(NULL, &v);
    BADV('N', v.maps == NULL);
}

static void args_visfield_save(void)
{
    begin("visfield_save");
    OK(hfvis_visfield_save(tmp_path("s.hfvf"), &vf_ok));
    BAD('N', INV, hfvis_visfield_save(NULL, &vf_ok));
    BAD('N', INV, hfvis_visfield_save(tmp_path("t.hfvf"), NULL));
    BAD('R', IOE, hfvis_visfield_save(bad_dir_path("t.hfvf"), &vf_ok));
    VF_CASES(hfvis_visfield_save(tmp_path("t.hfvf"), &bf));
    BADV('R', access(tmp_path("t.hfvf"), F_OK) != 0);
}

static void args_visfield_load(void)
{
    hfvis_visfield *v;
    begin("visfield_load");
    v = AT(hfvis_visfield);
    arena_fill();
    base_status(hfvis_visfield_load(tmp_path("s.hfvf"), NULL, v), __LINE__);
    hfvis_visfield_free(NULL, v);
    BAD('N', INV, hfvis_visfield_load(NULL, NULL, v));
    BAD('N', INV, hfvis_visfield_load(tmp_path("s.hfvf"), NULL, NULL));
    BAD('R', IOE, hfvis_visfield_load(tmp_path("missing.hfvf"), NULL, v));
}

/* ---- volume VPL indirect light ------------------------------------------------------------ */

static void args_volgi_sh_basis(void)
{
    double *o;
    begin("volgi_sh_basis");
    o = AD(4);
    OK(hfvis_volgi_sh_basis(v3_ok, o));
    BAD('N', INV, hfvis_volgi_sh_basis(NULL, o));
    BAD('N', INV, hfvis_volgi_sh_basis(v3_ok, NULL));
    BAD('Z', INV, hfvis_volgi_sh_basis(v3_zero, o));
    BAD('F', INV, hfvis_volgi_sh_basis(v3_nan, o));
}

static void args_volgi_sh_clamped_cosine(void)
{
    double *o;
    begin("volgi_sh_clamped_cosine");
    o = AD(4);
    OK(hfvis_volgi_sh_clamped_cosine(v3_ok, o));
    BAD('N', INV, hfvis_volgi_sh_clamped_cosine(NULL, o));
    BAD('N', INV, hfvis_volgi_sh_clamped_cosine(v3_ok, NULL));
    BAD('Z', INV, hfvis_volgi_sh_clamped_cosine(v3_zero, o));
    BAD('F', INV, hfvis_volgi_sh_clamped_cosine(v3_inf, o));
}

static void args_volgi_sh_cone(void)
{
    double *o;
    begin("volgi_sh_cone");
    o = AD(4);
    OK(hfvis_volgi_sh_cone(v3_ok, 0.7, o));
    BAD('N', INV, hfvis_volgi_sh_cone(NULL, 0.7, o));
    BAD('N', INV, hfvis_volgi_sh_cone(v3_ok, 0.7, NULL));
    BAD('Z', INV, hfvis_volgi_sh_cone(v3_zero, 0.7, o));
    BAD('Z', INV, hfvis_volgi_sh_cone(v3_ok, 0.0, o));
    BAD('G', INV, hfvis_volgi_sh_cone(v3_ok, -0.7, o));
    BAD('R', INV, hfvis_volgi_sh_cone(v3_ok, 3.5, o));
    BAD('F', INV, hfvis_volgi_sh_cone(v3_ok, (double)NAN, o));
}

static void args_volgi_options_default(void)
{
    hfvis_volgi_options o = hfvis_volgi_options_default();
    begin("volgi_options_default");
    CHECK(o.iterations > 0);
}

/* Invalid volgi options, substituted as &bo. */
#define VOLGI_OPT_CASES(expr) do { hfvis_volgi_options bo; \
    memset(&bo, 0, sizeof bo); bo.transfer = (hfvis_volgi_transfer)9; BAD('E', INV, expr); \
    memset(&bo, 0, sizeof bo); bo.reflection = (hfvis_volgi_reflection)-1; BAD('E', INV, expr); \
    memset(&bo, 0, sizeof bo); bo.paths = (hfvis_volgi_paths)7; BAD('E', INV, expr); \
    memset(&bo, 0, sizeof bo); bo.iterations = -1; BAD('G', INV, expr); \
    memset(&bo, 0, sizeof bo); bo.iterations = HFVIS_VOLGI_MAX_ITERATIONS + 1; BAD('O', INV, expr); \
    memset(&bo, 0, sizeof bo); bo.resolution = 1; BAD('S', INV, expr); \
    memset(&bo, 0, sizeof bo); bo.reflectance_source = HFVIS_VOLGI_REFLECTANCE_CONSTANT; bo.reflectance = 2.0f; BAD('S', INV, expr); \
    memset(&bo, 0, sizeof bo); bo.gather_scale = (double)NAN; BAD('F', INV, expr); \
    memset(&bo, 0, sizeof bo); bo.shadow_bias = -1.0; BAD('S', INV, expr); \
    memset(&bo, 0, sizeof bo); bo.reflectance_source = (hfvis_volgi_reflectance)9; BAD('E', INV, expr); \
    memset(&bo, 0, sizeof bo); bo.resolution = HFVIS_VOLGI_MAX_RESOLUTION + 1; BAD('O', INV, expr); \
    memset(&bo, 0, sizeof bo); bo.reflectance_source = HFVIS_VOLGI_REFLECTANCE_CONSTANT; bo.reflectance = (double)NAN; BAD('F', INV, expr); \
    memset(&bo, 0, sizeof bo); bo.shadow_bias = (double)INFINITY; BAD('F', INV, expr); \
    } while (0)

static void args_volgi_options_resolve(void)
{
    hfvis_volgi_options *o;
    begin("volgi_options_resolve");
    o = AT(hfvis_volgi_options);
    OK(hfvis_volgi_options_resolve(NULL, o));
    BAD('N', INV, hfvis_volgi_options_resolve(NULL, NULL));
    VOLGI_OPT_CASES(hfvis_volgi_options_resolve(&bo, o));
}

static float bad_occ[27], nan_nrm[81];

/* Invalid geometries, substituted as &bg3. */
#define GEO_CASES(expr) do { hfvis_volgi_geometry bg3; int i_; \
    for (i_ = 0; i_ < 27; i_++) bad_occ[i_] = 2.0f; \
    for (i_ = 0; i_ < 81; i_++) nan_nrm[i_] = (double)NAN; \
    bg3 = geo_ok; bg3.occupancy = NULL; BAD('N', INV, expr); \
    bg3 = geo_ok; bg3.normal = NULL; BAD('N', INV, expr); \
    bg3 = geo_ok; bg3.grid.dims[0] = 0; BAD('Z', INV, expr); \
    bg3 = geo_ok; bg3.grid.cell[1] = -1.0; BAD('G', INV, expr); \
    bg3 = geo_ok; bg3.occupancy = bad_occ; BAD('R', INV, expr); \
    bg3 = geo_ok; bg3.normal = nan_nrm; BAD('F', INV, expr); \
    bg3 = geo_ok; bg3.grid.dims[0] = bg3.grid.dims[1] = bg3.grid.dims[2] = 2048; BAD('O', INV, expr); \
    } while (0)

static void args_volgi_inject(void)
{
    static float rad_bad[81];
    float *prop;
    begin("volgi_inject");
    prop = AF(27 * 12);
    OK(hfvis_volgi_inject(&geo_ok, vg_rad, prop));
    BAD('N', INV, hfvis_volgi_inject(NULL, vg_rad, prop));
    BAD('N', INV, hfvis_volgi_inject(&geo_ok, NULL, prop));
    BAD('N', INV, hfvis_volgi_inject(&geo_ok, vg_rad, NULL));
    memcpy(rad_bad, vg_rad, sizeof rad_bad);
    rad_bad[0] = -1.0f; BAD('S', INV, hfvis_volgi_inject(&geo_ok, rad_bad, prop));
    rad_bad[0] = (double)INFINITY; BAD('S', INV, hfvis_volgi_inject(&geo_ok, rad_bad, prop));
    GEO_CASES(hfvis_volgi_inject(&bg3, vg_rad, prop));
}

static float prop_bad[27 * 12];

#define STEP_CASES(fn) do { \
    BAD('N', INV, fn(NULL, NULL, sh_prop, pout, acc, en)); \
    BAD('N', INV, fn(&geo_ok, NULL, NULL, pout, acc, en)); \
    BAD('N', INV, fn(&geo_ok, NULL, sh_prop, NULL, acc, en)); \
    BAD('N', INV, fn(&geo_ok, NULL, sh_prop, pout, NULL, en)); \
    memcpy(prop_bad, sh_prop, sizeof prop_bad); prop_bad[5] = (double)NAN; \
    BAD('S', INV, fn(&geo_ok, NULL, prop_bad, pout, acc, en)); \
    prop_bad[5] = 1e30f; BAD('S', INV, fn(&geo_ok, NULL, prop_bad, pout, acc, en)); \
    GEO_CASES(fn(&bg3, NULL, sh_prop, pout, acc, en)); \
    VOLGI_OPT_CASES(fn(&geo_ok, &bo, sh_prop, pout, acc, en)); \
    { hfvis_volgi_options ba; memset(&ba, 0, sizeof ba); ba.reflectance_source = HFVIS_VOLGI_REFLECTANCE_ALBEDO; \
      BAD('S', INV, fn(&geo_ok, &ba, sh_prop, pout, acc, en)); } \
    } while (0)

static void args_volgi_propagate_step(void)
{
    float *pout, *acc;
    hfvis_volgi_energy *en;
    begin("volgi_propagate_step");
    pout = AF(27 * 12); acc = AF(27 * 12); en = AT(hfvis_volgi_energy);
    arena_fill();
    memset(acc, 0, 27 * 12 * sizeof(float));
    base_status(hfvis_volgi_propagate_step(&geo_ok, NULL, sh_prop, pout, acc, en), __LINE__);
    STEP_CASES(hfvis_volgi_propagate_step);
}

static void args_volgi_propagate_step_reference(void)
{
    float *pout, *acc;
    hfvis_volgi_energy *en;
    begin("volgi_propagate_step_reference");
    pout = AF(27 * 12); acc = AF(27 * 12); en = AT(hfvis_volgi_energy);
    arena_fill();
    memset(acc, 0, 27 * 12 * sizeof(float));
    base_status(hfvis_volgi_propagate_step_reference(&geo_ok, NULL, sh_prop, pout, acc, en), __LINE__);
    STEP_CASES(hfvis_volgi_propagate_step_reference);
}

static void args_volgi_propagate(void)
{
    float *prop, *acc;
    hfvis_volgi_energy *en;
    begin("volgi_propagate");
    prop = AF(27 * 12); acc = AF(27 * 12); en = ATN(hfvis_volgi_energy, 2);
    arena_fill();
    memcpy(prop, sh_prop, sizeof sh_prop);
    memset(acc, 0, sizeof sh_accum);
    base_status(hfvis_volgi_propagate(&geo_ok, NULL, 2, prop, acc, en), __LINE__);
    /* inputs in the arena hold the sentinel pattern, a finite float (-2.9e-16): valid input */
    BAD('N', INV, hfvis_volgi_propagate(NULL, NULL, 2, prop, acc, en));
    BAD('N', INV, hfvis_volgi_propagate(&geo_ok, NULL, 2, NULL, acc, en));
    BAD('N', INV, hfvis_volgi_propagate(&geo_ok, NULL, 2, prop, NULL, en));
    BAD('G', INV, hfvis_volgi_propagate(&geo_ok, NULL, -1, prop, acc, en));
    BAD('O', INV, hfvis_volgi_propagate(&geo_ok, NULL, HFVIS_VOLGI_MAX_ITERATIONS + 1, prop, acc, en));
    BADP('F', INV, prop[100] = (double)NAN, hfvis_volgi_propagate(&geo_ok, NULL, 2, prop, acc, en));
    BADP('S', INV, acc[7] = 1e30f, hfvis_volgi_propagate(&geo_ok, NULL, 2, prop, acc, en));
    GEO_CASES(hfvis_volgi_propagate(&bg3, NULL, 2, prop, acc, en));
    VOLGI_OPT_CASES(hfvis_volgi_propagate(&geo_ok, &bo, 2, prop, acc, en));
}

static const double gp[3] = {1.5, 1.5, 1.2}, gn[3] = {0, 0, -1};

static void args_volgi_gather(void)
{
    float *irr;
    begin("volgi_gather");
    irr = AF(3);
    OK(hfvis_volgi_gather(&geo_ok, sh_accum, NULL, gp, gn, irr));
    BAD('N', INV, hfvis_volgi_gather(NULL, sh_accum, NULL, gp, gn, irr));
    BAD('N', INV, hfvis_volgi_gather(&geo_ok, NULL, NULL, gp, gn, irr));
    BAD('N', INV, hfvis_volgi_gather(&geo_ok, sh_accum, NULL, NULL, gn, irr));
    BAD('N', INV, hfvis_volgi_gather(&geo_ok, sh_accum, NULL, gp, NULL, irr));
    BAD('N', INV, hfvis_volgi_gather(&geo_ok, sh_accum, NULL, gp, gn, NULL));
    BAD('F', INV, hfvis_volgi_gather(&geo_ok, sh_accum, NULL, v3_nan, gn, irr));
    BAD('Z', INV, hfvis_volgi_gather(&geo_ok, sh_accum, NULL, gp, v3_zero, irr));
    {   /* the geometry's arrays are not re-checked (O(1) call): only the grid and pointers */
        hfvis_volgi_geometry bg3 = geo_ok;
        bg3.grid.dims[0] = 0; BAD('Z', INV, hfvis_volgi_gather(&bg3, sh_accum, NULL, gp, gn, irr));
        bg3 = geo_ok; bg3.grid.cell[0] = (double)NAN; BAD('F', INV, hfvis_volgi_gather(&bg3, sh_accum, NULL, gp, gn, irr));
        bg3 = geo_ok; bg3.occupancy = NULL; BAD('N', INV, hfvis_volgi_gather(&bg3, sh_accum, NULL, gp, gn, irr));
    }
    VOLGI_OPT_CASES(hfvis_volgi_gather(&geo_ok, sh_accum, &bo, gp, gn, irr));
}

static hfvis_volgi_light light_ok(void)
{
    hfvis_volgi_light l;
    memset(&l, 0, sizeof l);
    l.type = HFVIS_VOLGI_LIGHT_POINT;
    l.position[0] = 0.5; l.position[1] = 0.5; l.position[2] = 3.0;
    l.direction[2] = -1.0;
    l.intensity[0] = l.intensity[1] = l.intensity[2] = 1.0f;
    return l;
}

static hfvis_volgi_light sc_light;
static hfvis_volgi_scene scene_ok(void)
{
    hfvis_volgi_scene s;
    memset(&s, 0, sizeof s);
    sc_light = light_ok();
    s.mesh = &m_box; s.lights = &sc_light; s.light_count = 1; s.bvh = &m_bvh;
    return s;
}

static hfvis_volgi_light blight;
static float bmat[36];

/* Invalid scenes, substituted as &bs. */
#define SCENE_CASES(expr) do { hfvis_volgi_scene bs; int i_; \
    bs = scene_ok(); bs.mesh = NULL; BAD('N', INV, expr); \
    bs = scene_ok(); bs.bvh = &bad_bvh; BAD('R', INV, expr); \
    bs = scene_ok(); bs.light_count = -1; BAD('G', INV, expr); \
    bs = scene_ok(); bs.light_count = HFVIS_VOLGI_MAX_LIGHTS + 1; BAD('O', INV, expr); \
    bs = scene_ok(); blight = light_ok(); blight.type = (hfvis_volgi_light_type)9; bs.lights = &blight; BAD('E', INV, expr); \
    bs = scene_ok(); blight = light_ok(); blight.position[0] = (double)NAN; bs.lights = &blight; BAD('F', INV, expr); \
    bs = scene_ok(); blight = light_ok(); blight.intensity[1] = -1.0f; bs.lights = &blight; BAD('S', INV, expr); \
    (void)i_; \
    } while (0)
/* Invalid materials (voxelize and render read them; direct irradiance does not). */
#define MATERIAL_CASES(expr) do { hfvis_volgi_scene bs; int i_; \
    bs = scene_ok(); for (i_ = 0; i_ < 36; i_++) bmat[i_] = 2.0f; bs.albedo = bmat; BAD('S', INV, expr); \
    bs = scene_ok(); for (i_ = 0; i_ < 36; i_++) bmat[i_] = (double)NAN; bs.emission = bmat; BAD('F', INV, expr); \
    } while (0)

static void args_volgi_direct_irradiance(void)
{
    hfvis_volgi_scene sc = scene_ok();
    static const double p[3] = {0.5, 0.5, 1.0}, n[3] = {0, 0, 1};
    float *irr;
    begin("volgi_direct_irradiance");
    irr = AF(3);
    OK(hfvis_volgi_direct_irradiance(&sc, NULL, p, n, HFVIS_NO_TRIANGLE, irr));
    BAD('N', INV, hfvis_volgi_direct_irradiance(NULL, NULL, p, n, HFVIS_NO_TRIANGLE, irr));
    BAD('N', INV, hfvis_volgi_direct_irradiance(&sc, NULL, NULL, n, HFVIS_NO_TRIANGLE, irr));
    BAD('N', INV, hfvis_volgi_direct_irradiance(&sc, NULL, p, n, HFVIS_NO_TRIANGLE, NULL));
    BAD('F', INV, hfvis_volgi_direct_irradiance(&sc, NULL, p, v3_inf, HFVIS_NO_TRIANGLE, irr));
    BAD('Z', INV, hfvis_volgi_direct_irradiance(&sc, NULL, p, v3_zero, HFVIS_NO_TRIANGLE, irr));
    {   hfvis_volgi_scene bs = scene_ok(); bs.bvh = NULL;
        BAD('N', INV, hfvis_volgi_direct_irradiance(&bs, NULL, p, n, HFVIS_NO_TRIANGLE, irr)); }
    SCENE_CASES(hfvis_volgi_direct_irradiance(&bs, NULL, p, n, HFVIS_NO_TRIANGLE, irr));
    VOLGI_OPT_CASES(hfvis_volgi_direct_irradiance(&sc, &bo, p, n, HFVIS_NO_TRIANGLE, irr));
}

static void args_volgi_grid_fit(void)
{
    hfvis_volume_grid *g;
    begin("volgi_grid_fit");
    g = AT(hfvis_volume_grid);
    OK(hfvis_volgi_grid_fit(&m_box, 4, g));
    BAD('N', INV, hfvis_volgi_grid_fit(NULL, 4, g));
    BAD('N', INV, hfvis_volgi_grid_fit(&m_box, 4, NULL));
    BAD('Z', INV, hfvis_volgi_grid_fit(&m_box, 0, g));
    BAD('R', INV, hfvis_volgi_grid_fit(&m_box, 1, g));
    BAD('O', INV, hfvis_volgi_grid_fit(&m_box, HFVIS_VOLGI_MAX_RESOLUTION + 1, g));
    MESH_CASES(hfvis_volgi_grid_fit(&bm, 4, g), INV);
}

static void args_volgi_voxelize(void)
{
    hfvis_volgi_scene sc = scene_ok();
    float *occ, *nrm, *alb, *rad;
    size_t *fr;
    begin("volgi_voxelize");
    occ = AF(64); nrm = AF(192); alb = AF(192); rad = AF(192); fr = AT(size_t);
    OK(hfvis_volgi_voxelize(&sc, &vg_ok, NULL, occ, nrm, alb, rad, fr));
    OK(hfvis_volgi_voxelize(&sc, &vg_ok, NULL, occ, nrm, NULL, rad, NULL));
    BAD('N', INV, hfvis_volgi_voxelize(NULL, &vg_ok, NULL, occ, nrm, alb, rad, fr));
    BAD('N', INV, hfvis_volgi_voxelize(&sc, NULL, NULL, occ, nrm, alb, rad, fr));
    BAD('N', INV, hfvis_volgi_voxelize(&sc, &vg_ok, NULL, NULL, nrm, alb, rad, fr));
    BAD('N', INV, hfvis_volgi_voxelize(&sc, &vg_ok, NULL, occ, NULL, alb, rad, fr));
    BAD('N', INV, hfvis_volgi_voxelize(&sc, &vg_ok, NULL, occ, nrm, alb, NULL, fr));
    SCENE_CASES(hfvis_volgi_voxelize(&bs, &vg_ok, NULL, occ, nrm, alb, rad, fr));
    MATERIAL_CASES(hfvis_volgi_voxelize(&bs, &vg_ok, NULL, occ, nrm, alb, rad, fr));
    VGRID_CASES(hfvis_volgi_voxelize(&sc, &bv, NULL, occ, nrm, alb, rad, fr), INV);
    VOLGI_OPT_CASES(hfvis_volgi_voxelize(&sc, &vg_ok, &bo, occ, nrm, alb, rad, fr));
}

static void args_volgi_render(void)
{
    hfvis_volgi_scene sc = scene_ok();
    hfvis_volgi_options o;
    hfvis_volgi_outputs out;
    hfvis_volgi_render_info *info;
    begin("volgi_render");
    memset(&o, 0, sizeof o);
    o.iterations = 2; o.resolution = 4;
    out.direct = AF(192); out.indirect = AF(192); out.total = AF(192);
    info = AT(hfvis_volgi_render_info);
    OK(hfvis_volgi_render(&sc, NULL, &view_ok, &o, &out, info));
    OK(hfvis_volgi_render(&sc, &vg_ok, &view_ok, &o, &out, NULL));
    BAD('N', INV, hfvis_volgi_render(NULL, NULL, &view_ok, &o, &out, info));
    BAD('N', INV, hfvis_volgi_render(&sc, NULL, NULL, &o, &out, info));
    BAD('N', INV, hfvis_volgi_render(&sc, NULL, &view_ok, &o, NULL, info));
    SCENE_CASES(hfvis_volgi_render(&bs, NULL, &view_ok, &o, &out, info));
    MATERIAL_CASES(hfvis_volgi_render(&bs, NULL, &view_ok, &o, &out, info));
    VGRID_CASES(hfvis_volgi_render(&sc, &bv, &view_ok, &o, &out, info), INV);
    VIEW_CASES(hfvis_volgi_render(&sc, NULL, &bw, &o, &out, info));
    VOLGI_OPT_CASES(hfvis_volgi_render(&sc, NULL, &view_ok, &bo, &out, info));
}

/* ---- Laine-Karras bitmask AO ------------------------------------------------------------ */

static void args_lk_ray_options_default(void)
{
    hfvis_lk_ray_options o = hfvis_lk_ray_options_default();
    begin("lk_ray_options_default");
    CHECK(o.alloc == NULL);
}

static double incr_falloff(void *user, double x)
{
    (void)user;
    return x;
}

static void args_lk_rays_build(void)
{
    hfvis_lk_ray_options o = hfvis_lk_ray_options_default(), b;
    hfvis_lk_rays *r;
    begin("lk_rays_build");
    o.pattern = HFVIS_LK_PATTERN_RANDOM;
    r = AT(hfvis_lk_rays);
    arena_fill();
    base_status(hfvis_lk_rays_build(8, 1.0, &o, r), __LINE__);
    hfvis_lk_rays_free(NULL, r);
    BAD('N', INV, hfvis_lk_rays_build(8, 1.0, &o, NULL));
    BAD('Z', INV, hfvis_lk_rays_build(0, 1.0, &o, r));
    BAD('O', INV, hfvis_lk_rays_build(HFVIS_LK_MAX_RAYS + 1, 1.0, &o, r));
    BAD('Z', INV, hfvis_lk_rays_build(8, 0.0, &o, r));
    BAD('G', INV, hfvis_lk_rays_build(8, -1.0, &o, r));
    BAD('F', INV, hfvis_lk_rays_build(8, (double)INFINITY, &o, r));
    b = o; b.pattern = (hfvis_lk_pattern)9; BAD('E', INV, hfvis_lk_rays_build(8, 1.0, &b, r));
    b = o; b.falloff = (hfvis_lk_falloff)-1; BAD('E', INV, hfvis_lk_rays_build(8, 1.0, &b, r));
    b = o; b.lloyd_iterations = -1; BAD('S', INV, hfvis_lk_rays_build(8, 1.0, &b, r));
    b = o; b.density_resolution = 8; BAD('S', INV, hfvis_lk_rays_build(8, 1.0, &b, r));
    b = o; b.falloff = HFVIS_LK_FALLOFF_CUSTOM; BAD('N', INV, hfvis_lk_rays_build(8, 1.0, &b, r));
    b = o; b.falloff = HFVIS_LK_FALLOFF_CUSTOM; b.falloff_fn = incr_falloff;
    BAD('S', INV, hfvis_lk_rays_build(8, 1.0, &b, r));
}

static const double lk_dirs[6] = {0, 0, 1, 0.5, 0, 1}, lk_len[2] = {1.0, 0.5};

static void args_lk_rays_custom(void)
{
    static const double dzero[6] = {0, 0, 0, 0, 0, 1}, ddown[6] = {0, 0, -1, 0, 0, 1}, dnan[6] = {0, (double)NAN, 1, 0, 0, 1};
    static const double lbad[2] = {1.0, 1.5};
    hfvis_lk_rays *r;
    begin("lk_rays_custom");
    r = AT(hfvis_lk_rays);
    arena_fill();
    base_status(hfvis_lk_rays_custom(2, 1.0, lk_dirs, lk_len, NULL, r), __LINE__);
    hfvis_lk_rays_free(NULL, r);
    BAD('N', INV, hfvis_lk_rays_custom(2, 1.0, NULL, lk_len, NULL, r));
    BAD('N', INV, hfvis_lk_rays_custom(2, 1.0, lk_dirs, lk_len, NULL, NULL));
    BAD('Z', INV, hfvis_lk_rays_custom(0, 1.0, lk_dirs, lk_len, NULL, r));
    BAD('O', INV, hfvis_lk_rays_custom(HFVIS_LK_MAX_RAYS + 1, 1.0, lk_dirs, lk_len, NULL, r));
    BAD('G', INV, hfvis_lk_rays_custom(2, -1.0, lk_dirs, lk_len, NULL, r));
    BAD('F', INV, hfvis_lk_rays_custom(2, (double)NAN, lk_dirs, lk_len, NULL, r));
    BAD('Z', INV, hfvis_lk_rays_custom(2, 1.0, dzero, lk_len, NULL, r));
    BAD('R', INV, hfvis_lk_rays_custom(2, 1.0, ddown, lk_len, NULL, r));
    BAD('F', INV, hfvis_lk_rays_custom(2, 1.0, dnan, lk_len, NULL, r));
    BAD('R', INV, hfvis_lk_rays_custom(2, 1.0, lk_dirs, lbad, NULL, r));
}

static void args_lk_rays_free(void)
{
    hfvis_lk_rays r;
    begin("lk_rays_free");
    memset(&r, 0, sizeof r);
    hfvis_lk_rays_free(NULL, NULL);
    hfvis_lk_rays_free(NULL, &r);
    BADV('N', r.direction == NULL);
}

static void args_lk_mask_words(void)
{
    begin("lk_mask_words");
    CHECK(hfvis_lk_mask_words(33) == 2);
    BADV('Z', hfvis_lk_mask_words(0) == 0);
    BADV('G', hfvis_lk_mask_words(-1) == 0);
    BADV('O', hfvis_lk_mask_words(HFVIS_LK_MAX_RAYS + 1) == 0);
}

static void args_lk_obscurance(void)
{
    static const uint32_t m[1] = {3u};
    begin("lk_obscurance");
    CHECK(hfvis_lk_obscurance(m, 4) == 0.5);
    BADV('N', isnan(hfvis_lk_obscurance(NULL, 4)));
    BADV('Z', isnan(hfvis_lk_obscurance(m, 0)));
    BADV('O', isnan(hfvis_lk_obscurance(m, HFVIS_LK_MAX_RAYS + 1)));
}

/* Invalid ray sets, substituted as &bry. */
#define RAYSET_CASES(expr) do { hfvis_lk_rays bry; \
    bry = lk_rays; bry.direction = NULL; BAD('N', INV, expr); \
    bry = lk_rays; bry.count = 0; BAD('Z', INV, expr); \
    bry = lk_rays; bry.words = 7; BAD('S', INV, expr); \
    bry = lk_rays; bry.radius = (double)NAN; BAD('F', INV, expr); \
    } while (0)

static void args_lk_frame(void)
{
    double *f;
    begin("lk_frame");
    f = AD(9);
    OK(hfvis_lk_frame(&lk_rays, v3_ok, 1, 2, HFVIS_LK_JITTER_DEFAULT, 0.0, 0.0, f));
    OK(hfvis_lk_frame(&lk_rays, v3_ok, 1, 2, HFVIS_LK_JITTER_CUSTOM, 1.0, 0.01, f));
    BAD('N', INV, hfvis_lk_frame(NULL, v3_ok, 1, 2, HFVIS_LK_JITTER_DEFAULT, 0.0, 0.0, f));
    BAD('N', INV, hfvis_lk_frame(&lk_rays, NULL, 1, 2, HFVIS_LK_JITTER_DEFAULT, 0.0, 0.0, f));
    BAD('N', INV, hfvis_lk_frame(&lk_rays, v3_ok, 1, 2, HFVIS_LK_JITTER_DEFAULT, 0.0, 0.0, NULL));
    BAD('Z', INV, hfvis_lk_frame(&lk_rays, v3_zero, 1, 2, HFVIS_LK_JITTER_DEFAULT, 0.0, 0.0, f));
    BAD('F', INV, hfvis_lk_frame(&lk_rays, v3_nan, 1, 2, HFVIS_LK_JITTER_DEFAULT, 0.0, 0.0, f));
    BAD('E', INV, hfvis_lk_frame(&lk_rays, v3_ok, 1, 2, (hfvis_lk_jitter)9, 0.0, 0.0, f));
    BAD('R', INV, hfvis_lk_frame(&lk_rays, v3_ok, 1, 2, HFVIS_LK_JITTER_CUSTOM, 4.0, 0.0, f));
    BAD('G', INV, hfvis_lk_frame(&lk_rays, v3_ok, 1, 2, HFVIS_LK_JITTER_CUSTOM, 1.0, -0.1, f));
    BAD('F', INV, hfvis_lk_frame(&lk_rays, v3_ok, 1, 2, HFVIS_LK_JITTER_CUSTOM, (double)NAN, 0.0, f));
    RAYSET_CASES(hfvis_lk_frame(&bry, v3_ok, 1, 2, HFVIS_LK_JITTER_DEFAULT, 0.0, 0.0, f));
}

static void args_lk_lut_bytes(void)
{
    begin("lk_lut_bytes");
    CHECK(hfvis_lk_lut_bytes(4, 32, 0) == 4 * 4 * 4 * 4);
    BADV('Z', hfvis_lk_lut_bytes(0, 32, 0) == 0);
    BADV('G', hfvis_lk_lut_bytes(4, -32, 0) == 0);
    BADV('R', hfvis_lk_lut_bytes(1, 32, 0) == 0);
    BADV('O', hfvis_lk_lut_bytes(HFVIS_LK_LUT_MAX_RESOLUTION + 1, 32, 1) == 0);
}

static void args_lk_lut_build(void)
{
    hfvis_lk_lut *l;
    begin("lk_lut_build");
    l = AT(hfvis_lk_lut);
    arena_fill();
    base_status(hfvis_lk_lut_build(&lk_rays, 4, NULL, l), __LINE__);
    hfvis_lk_lut_free(NULL, l);
    BAD('N', INV, hfvis_lk_lut_build(NULL, 4, NULL, l));
    BAD('N', INV, hfvis_lk_lut_build(&lk_rays, 4, NULL, NULL));
    BAD('R', INV, hfvis_lk_lut_build(&lk_rays, 1, NULL, l));
    BAD('G', INV, hfvis_lk_lut_build(&lk_rays, -4, NULL, l));
    BAD('O', INV, hfvis_lk_lut_build(&lk_rays, HFVIS_LK_LUT_MAX_RESOLUTION + 1, NULL, l));
    RAYSET_CASES(hfvis_lk_lut_build(&bry, 4, NULL, l));
}

static void args_lk_lut_free(void)
{
    hfvis_lk_lut l;
    begin("lk_lut_free");
    memset(&l, 0, sizeof l);
    hfvis_lk_lut_free(NULL, NULL);
    hfvis_lk_lut_free(NULL, &l);
    BADV('N', l.masks == NULL);
}

static void args_lk_lut_index(void)
{
    int *ijk;
    begin("lk_lut_index");
    ijk = ATN(int, 3);
    OK(hfvis_lk_lut_index(4, v3_ok, 0.5, ijk));
    BAD('N', INV, hfvis_lk_lut_index(4, NULL, 0.5, ijk));
    BAD('N', INV, hfvis_lk_lut_index(4, v3_ok, 0.5, NULL));
    BAD('R', INV, hfvis_lk_lut_index(1, v3_ok, 0.5, ijk));
    BAD('O', INV, hfvis_lk_lut_index(HFVIS_LK_LUT_MAX_RESOLUTION + 1, v3_ok, 0.5, ijk));
    BAD('Z', INV, hfvis_lk_lut_index(4, v3_zero, 0.5, ijk));
    BAD('F', INV, hfvis_lk_lut_index(4, v3_nan, 0.5, ijk));
    BAD('F', INV, hfvis_lk_lut_index(4, v3_ok, (double)NAN, ijk));
}

static void args_lk_lut_fetch(void)
{
    begin("lk_lut_fetch");
    CHECK(hfvis_lk_lut_fetch(&lut_ok, 0, v3_ok, 0.5) != NULL);
    BADV('N', hfvis_lk_lut_fetch(NULL, 0, v3_ok, 0.5) == NULL);
    BADV('N', hfvis_lk_lut_fetch(&lut_ok, 0, NULL, 0.5) == NULL);
    BADV('Z', hfvis_lk_lut_fetch(&lut_ok, 0, v3_zero, 0.5) == NULL);
    BADV('F', hfvis_lk_lut_fetch(&lut_ok, 0, v3_ok, (double)INFINITY) == NULL);
}

static void args_lk_plane_mask(void)
{
    uint32_t *m;
    begin("lk_plane_mask");
    m = ATN(uint32_t, 1);
    OK(hfvis_lk_plane_mask(&lk_rays, v3_ok, 0.5, m));
    BAD('N', INV, hfvis_lk_plane_mask(NULL, v3_ok, 0.5, m));
    BAD('N', INV, hfvis_lk_plane_mask(&lk_rays, NULL, 0.5, m));
    BAD('N', INV, hfvis_lk_plane_mask(&lk_rays, v3_ok, 0.5, NULL));
    BAD('F', INV, hfvis_lk_plane_mask(&lk_rays, v3_nan, 0.5, m));
    BAD('F', INV, hfvis_lk_plane_mask(&lk_rays, v3_ok, (double)NAN, m));
    RAYSET_CASES(hfvis_lk_plane_mask(&bry, v3_ok, 0.5, m));
}

static const double lk_pos[3] = {0.2, 0.2, 0.0};
static double lk_frm[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
static const float lv0[3] = {-1, -1, 0.2f}, lv1[3] = {1, -1, 0.2f}, lv2[3] = {0, 1, 0.2f};

static void args_lk_triangle_mask(void)
{
    static const double fnan[9] = {1, 0, 0, 0, (double)NAN, 0, 0, 0, 1};
    hfvis_lk_lut other = lut_ok;
    uint32_t *m;
    hfvis_lk_verdict *v;
    begin("lk_triangle_mask");
    m = ATN(uint32_t, 1); v = AT(hfvis_lk_verdict);
    OK(hfvis_lk_triangle_mask(&lk_rays, NULL, lk_pos, lk_frm, lv0, lv1, lv2, 0, 0.0, 0.5, 1e-6, m, v));
    OK(hfvis_lk_triangle_mask(&lk_rays, &lut_ok, lk_pos, lk_frm, lv0, lv1, lv2, 1, 0.0, 0.5, 1e-6, m, NULL));
    BAD('N', INV, hfvis_lk_triangle_mask(NULL, NULL, lk_pos, lk_frm, lv0, lv1, lv2, 0, 0.0, 0.5, 1e-6, m, v));
    BAD('N', INV, hfvis_lk_triangle_mask(&lk_rays, NULL, NULL, lk_frm, lv0, lv1, lv2, 0, 0.0, 0.5, 1e-6, m, v));
    BAD('N', INV, hfvis_lk_triangle_mask(&lk_rays, NULL, lk_pos, NULL, lv0, lv1, lv2, 0, 0.0, 0.5, 1e-6, m, v));
    BAD('N', INV, hfvis_lk_triangle_mask(&lk_rays, NULL, lk_pos, lk_frm, NULL, lv1, lv2, 0, 0.0, 0.5, 1e-6, m, v));
    BAD('N', INV, hfvis_lk_triangle_mask(&lk_rays, NULL, lk_pos, lk_frm, lv0, lv1, lv2, 0, 0.0, 0.5, 1e-6, NULL, v));
    BAD('F', INV, hfvis_lk_triangle_mask(&lk_rays, NULL, lk_pos, fnan, lv0, lv1, lv2, 0, 0.0, 0.5, 1e-6, m, v));
    BAD('F', INV, hfvis_lk_triangle_mask(&lk_rays, NULL, lk_pos, lk_frm, lv0, tvn, lv2, 0, 0.0, 0.5, 1e-6, m, v));
    BAD('R', INV, hfvis_lk_triangle_mask(&lk_rays, NULL, lk_pos, lk_frm, lv0, lv1, lv2, 0, 0.4, 0.3, 1e-6, m, v));
    BAD('O', INV, hfvis_lk_triangle_mask(&lk_rays, NULL, lk_pos, lk_frm, lv0, lv1, lv2, 0, 0.0, 0.6, 1e-6, m, v));
    BAD('G', INV, hfvis_lk_triangle_mask(&lk_rays, NULL, lk_pos, lk_frm, lv0, lv1, lv2, 0, -0.1, 0.5, 1e-6, m, v));
    BAD('Z', INV, hfvis_lk_triangle_mask(&lk_rays, NULL, lk_pos, lk_frm, lv0, lv1, lv2, 0, 0.0, 0.5, 0.0, m, v));
    other.count = 64;
    BAD('S', INV, hfvis_lk_triangle_mask(&lk_rays, &other, lk_pos, lk_frm, lv0, lv1, lv2, 0, 0.0, 0.5, 1e-6, m, v));
    RAYSET_CASES(hfvis_lk_triangle_mask(&bry, NULL, lk_pos, lk_frm, lv0, lv1, lv2, 0, 0.0, 0.5, 1e-6, m, v));
}

static void args_lk_options_default(void)
{
    hfvis_lk_options o = hfvis_lk_options_default();
    begin("lk_options_default");
    CHECK(o.epsilon == 0.0);
}

/* Invalid LK options, substituted as &bk. */
#define LKOPT_CASES(expr) do { hfvis_lk_options bk; \
    bk = hfvis_lk_options_default(); bk.mask_mode = (hfvis_lk_mask_mode)9; BAD('E', INV, expr); \
    bk = hfvis_lk_options_default(); bk.sides = (hfvis_lk_sides)-1; BAD('E', INV, expr); \
    bk = hfvis_lk_options_default(); bk.cull = 0x40u; BAD('S', INV, expr); \
    bk = hfvis_lk_options_default(); bk.epsilon = -1.0; BAD('G', INV, expr); \
    bk = hfvis_lk_options_default(); bk.alpha = (double)NAN; BAD('F', INV, expr); \
    bk = hfvis_lk_options_default(); bk.mask_mode = HFVIS_LK_MASK_LUT; BAD('N', INV, expr); \
    bk = hfvis_lk_options_default(); bk.sides = HFVIS_LK_SIDES_PER_TRIANGLE; BAD('N', INV, expr); \
    bk = hfvis_lk_options_default(); bk.jitter = HFVIS_LK_JITTER_CUSTOM; bk.tilt_max_rad = 2.0; BAD('R', INV, expr); \
    bk = hfvis_lk_options_default(); bk.jitter = (hfvis_lk_jitter)9; BAD('E', INV, expr); \
    bk = hfvis_lk_options_default(); bk.node_mask = (hfvis_lk_node_mask)9; BAD('E', INV, expr); \
    bk = hfvis_lk_options_default(); bk.volume = (hfvis_lk_volume)9; BAD('E', INV, expr); \
    bk = hfvis_lk_options_default(); bk.raycast_test = (hfvis_lk_raycast_test)9; BAD('E', INV, expr); \
    bk = hfvis_lk_options_default(); bk.gbuffer_cull = (hfvis_cull_mode)9; BAD('E', INV, expr); \
    bk = hfvis_lk_options_default(); bk.node_mask = HFVIS_LK_NODE_SPHERE_LUT; BAD('N', INV, expr); \
    bk = hfvis_lk_options_default(); bk.epsilon = (double)INFINITY; BAD('F', INV, expr); \
    } while (0)

static void args_lk_options_resolve(void)
{
    hfvis_lk_options *o;
    begin("lk_options_resolve");
    o = AT(hfvis_lk_options);
    OK(hfvis_lk_options_resolve(NULL, 0.5, o));
    BAD('N', INV, hfvis_lk_options_resolve(NULL, 0.5, NULL));
    BAD('Z', INV, hfvis_lk_options_resolve(NULL, 0.0, o));
    BAD('F', INV, hfvis_lk_options_resolve(NULL, (double)INFINITY, o));
    LKOPT_CASES(hfvis_lk_options_resolve(&bk, 0.5, o));
}

static void args_lk_gbuffer_receivers(void)
{
    double *pos, *nrm;
    uint64_t *key;
    size_t *cnt;
    begin("lk_gbuffer_receivers");
    pos = AD(3 * 64); nrm = AD(3 * 64); key = ATN(uint64_t, 64); cnt = AT(size_t);
    OK(hfvis_lk_gbuffer_receivers(&m_box, &view_ok, NULL, pos, nrm, key, cnt));
    OK(hfvis_lk_gbuffer_receivers(&m_box, &view_ok, NULL, pos, nrm, NULL, cnt));
    BAD('N', INV, hfvis_lk_gbuffer_receivers(NULL, &view_ok, NULL, pos, nrm, key, cnt));
    BAD('N', INV, hfvis_lk_gbuffer_receivers(&m_box, NULL, NULL, pos, nrm, key, cnt));
    BAD('N', INV, hfvis_lk_gbuffer_receivers(&m_box, &view_ok, NULL, NULL, nrm, key, cnt));
    BAD('N', INV, hfvis_lk_gbuffer_receivers(&m_box, &view_ok, NULL, pos, NULL, key, cnt));
    BAD('N', INV, hfvis_lk_gbuffer_receivers(&m_box, &view_ok, NULL, pos, nrm, key, NULL));
    MESH_CASES(hfvis_lk_gbuffer_receivers(&bm, &view_ok, NULL, pos, nrm, key, cnt), LIM);
    VIEW_CASES(hfvis_lk_gbuffer_receivers(&m_box, &bw, NULL, pos, nrm, key, cnt));
    {   hfvis_lk_options bk = hfvis_lk_options_default(); bk.gbuffer_cull = (hfvis_cull_mode)9;
        BAD('E', INV, hfvis_lk_gbuffer_receivers(&m_box, &view_ok, &bk, pos, nrm, key, cnt)); }
}

static void args_lk_raster(void)
{
    uint32_t *masks;
    float *ob;
    hfvis_lk_stats *st;
    begin("lk_raster");
    masks = ATN(uint32_t, 64); ob = AF(64); st = AT(hfvis_lk_stats);
    OK(hfvis_lk_raster(&m_box, &view_ok, &lk_rays, NULL, masks, ob, st));
    OK(hfvis_lk_raster(&m_box, &view_ok, &lk_rays, NULL, NULL, ob, NULL));
    BAD('N', INV, hfvis_lk_raster(NULL, &view_ok, &lk_rays, NULL, masks, ob, st));
    BAD('N', INV, hfvis_lk_raster(&m_box, NULL, &lk_rays, NULL, masks, ob, st));
    BAD('N', INV, hfvis_lk_raster(&m_box, &view_ok, NULL, NULL, masks, ob, st));
    BAD('N', INV, hfvis_lk_raster(&m_box, &view_ok, &lk_rays, NULL, NULL, NULL, st));
    MESH_CASES(hfvis_lk_raster(&bm, &view_ok, &lk_rays, NULL, masks, ob, st), INV);
    VIEW_CASES(hfvis_lk_raster(&m_box, &bw, &lk_rays, NULL, masks, ob, st));
    RAYSET_CASES(hfvis_lk_raster(&m_box, &view_ok, &bry, NULL, masks, ob, st));
    LKOPT_CASES(hfvis_lk_raster(&m_box, &view_ok, &lk_rays, &bk, masks, ob, st));
}

static const double rc_pos[6] = {0.5, 0.5, 1.0, 0.5, 0.5, -1.0}, rc_nrm[6] = {0, 0, 1, 0, 0, -1};
static const double rc_nan[6] = {0.5, 0.5, (double)NAN, 0.5, 0.5, -1.0}, rc_zero[6] = {0, 0, 0, 0, 0, -1};
static const double rc_nan2[6] = {0.5, 0.5, 1.0, 0.5, (double)NAN, -1.0}, rc_zero2[6] = {0, 0, 1, 0, 0, 0};

static hfvis_lk_receivers recv_ok(void)
{
    hfvis_lk_receivers r;
    r.count = 2; r.position = rc_pos; r.normal = rc_nrm; r.key = NULL;
    return r;
}

/* The shared cases of Method 2 and the ray caster: fn(mesh, bvh, rays, recv, opts, masks, ob, st). */
#define LK_RECV_CASES(fn) do { hfvis_lk_receivers brc; \
    BAD('N', INV, fn(NULL, &m_bvh, &lk_rays, &rc, NULL, masks, ob, st)); \
    BAD('N', INV, fn(&m_box, NULL, &lk_rays, &rc, NULL, masks, ob, st)); \
    BAD('N', INV, fn(&m_box, &m_bvh, NULL, &rc, NULL, masks, ob, st)); \
    BAD('N', INV, fn(&m_box, &m_bvh, &lk_rays, NULL, NULL, masks, ob, st)); \
    BAD('N', INV, fn(&m_box, &m_bvh, &lk_rays, &rc, NULL, NULL, NULL, st)); \
    brc = rc; brc.position = NULL; BAD('N', INV, fn(&m_box, &m_bvh, &lk_rays, &brc, NULL, masks, ob, st)); \
    brc = rc; brc.position = rc_nan; BAD('F', INV, fn(&m_box, &m_bvh, &lk_rays, &brc, NULL, masks, ob, st)); \
    brc = rc; brc.normal = rc_zero; BAD('Z', INV, fn(&m_box, &m_bvh, &lk_rays, &brc, NULL, masks, ob, st)); \
    brc = rc; brc.count = SIZE_MAX / 2; BAD('O', INV, fn(&m_box, &m_bvh, &lk_rays, &brc, NULL, masks, ob, st)); \
    brc = rc; brc.position = rc_nan2; BAD('F', INV, fn(&m_box, &m_bvh, &lk_rays, &brc, NULL, masks, ob, st)); \
    brc = rc; brc.normal = rc_zero2; BAD('Z', INV, fn(&m_box, &m_bvh, &lk_rays, &brc, NULL, masks, ob, st)); \
    BAD('R', INV, fn(&m_box, &bad_bvh, &lk_rays, &rc, NULL, masks, ob, st)); \
    RAYSET_CASES(fn(&m_box, &m_bvh, &bry, &rc, NULL, masks, ob, st)); \
    LKOPT_CASES(fn(&m_box, &m_bvh, &lk_rays, &rc, &bk, masks, ob, st)); \
    } while (0)

static void args_lk_bvh(void)
{
    hfvis_lk_receivers rc = recv_ok();
    uint32_t *masks;
    float *ob;
    hfvis_lk_stats *st;
    begin("lk_bvh");
    masks = ATN(uint32_t, 2); ob = AF(2); st = AT(hfvis_lk_stats);
    OK(hfvis_lk_bvh(&m_box, &m_bvh, &lk_rays, &rc, NULL, masks, ob, st));
    LK_RECV_CASES(hfvis_lk_bvh);
}

static void args_lk_reference(void)
{
    hfvis_lk_receivers rc = recv_ok();
    uint32_t *masks;
    float *ob;
    hfvis_lk_stats *st;
    begin("lk_reference");
    masks = ATN(uint32_t, 2); ob = AF(2); st = AT(hfvis_lk_stats);
    OK(hfvis_lk_reference(&m_box, &m_bvh, &lk_rays, &rc, NULL, masks, ob, st));
    LK_RECV_CASES(hfvis_lk_reference);
}

static void args_lk_image(void)
{
    uint32_t *masks;
    float *ob;
    hfvis_lk_stats *st;
    begin("lk_image");
    masks = ATN(uint32_t, 64); ob = AF(64); st = AT(hfvis_lk_stats);
    OK(hfvis_lk_image(HFVIS_LK_METHOD_BVH, &m_box, NULL, &view_ok, &lk_rays, NULL, masks, ob, st));
    OK(hfvis_lk_image(HFVIS_LK_METHOD_RASTER, &m_box, NULL, &view_ok, &lk_rays, NULL, masks, ob, st));
    BAD('E', INV, hfvis_lk_image((hfvis_lk_method)0, &m_box, NULL, &view_ok, &lk_rays, NULL, masks, ob, st));
    BAD('E', INV, hfvis_lk_image((hfvis_lk_method)9, &m_box, NULL, &view_ok, &lk_rays, NULL, masks, ob, st));
    BAD('N', INV, hfvis_lk_image(HFVIS_LK_METHOD_RAYCAST, NULL, NULL, &view_ok, &lk_rays, NULL, masks, ob, st));
    BAD('N', INV, hfvis_lk_image(HFVIS_LK_METHOD_RAYCAST, &m_box, NULL, NULL, &lk_rays, NULL, masks, ob, st));
    BAD('N', INV, hfvis_lk_image(HFVIS_LK_METHOD_RAYCAST, &m_box, NULL, &view_ok, NULL, NULL, masks, ob, st));
    BAD('N', INV, hfvis_lk_image(HFVIS_LK_METHOD_RAYCAST, &m_box, NULL, &view_ok, &lk_rays, NULL, NULL, NULL, st));
    BAD('R', INV, hfvis_lk_image(HFVIS_LK_METHOD_BVH, &m_box, &bad_bvh, &view_ok, &lk_rays, NULL, masks, ob, st));
    MESH_CASES(hfvis_lk_image(HFVIS_LK_METHOD_BVH, &bm, NULL, &view_ok, &lk_rays, NULL, masks, ob, st), INV);
    VIEW_CASES(hfvis_lk_image(HFVIS_LK_METHOD_RASTER, &m_box, NULL, &bw, &lk_rays, NULL, masks, ob, st));
    RAYSET_CASES(hfvis_lk_image(HFVIS_LK_METHOD_BVH, &m_box, NULL, &view_ok, &bry, NULL, masks, ob, st));
    LKOPT_CASES(hfvis_lk_image(HFVIS_LK_METHOD_RAYCAST, &m_box, NULL, &view_ok, &lk_rays, &bk, masks, ob, st));
}

/* ========================================================================================== */
/* Failing-allocator sweep                                                                    */
/* ========================================================================================== */

/* One call of each allocating function with allocator al and tiny valid inputs; outputs come
 * from the arena; an object returned on success is released again with al. */
#define SW(name) static hfvis_status sw_##name(const hfvis_allocator *al)

static hfvis_sweep_options sweep_opts(const hfvis_allocator *al)
{
    hfvis_sweep_options o = hfvis_sweep_options_default();
    o.alloc = al;
    return o;
}

SW(image_load)
{
    float **px = AT(float *);
    hfvis_image_info *info = AT(hfvis_image_info);
    hfvis_status s = hfvis_image_load(tmp_path("a.pgm"), al, px, info);
    if (s == HFVIS_OK) hfvis_free(al, *px);
    return s;
}
SW(horizon_lattice)
{
    hfvis_sweep_options o = sweep_opts(al);
    hfvis_lattice L;
    hfvis_lattice_init(&L, GW, GH, 0.3);
    return hfvis_horizon_lattice(&g_ok, 0.3, &o, AF(hfvis_lattice_nodes(&L)));
}
SW(horizon_lattice_naive)
{
    hfvis_sweep_options o = sweep_opts(al);
    hfvis_lattice L;
    hfvis_lattice_init(&L, GW, GH, 0.3);
    return hfvis_horizon_lattice_naive(&g_ok, 0.3, &o, AF(hfvis_lattice_nodes(&L)));
}
SW(horizon_direction) { hfvis_sweep_options o = sweep_opts(al); return hfvis_horizon_direction(&g_ok, 4, 1, &o, AF(GW * GH), GW); }
SW(openness) { hfvis_sweep_options o = sweep_opts(al); return hfvis_openness(&g_ok, 4, NULL, &o, AF(GW * GH), GW); }
/* both signs by the sweep (radius 0): two runs, and a failure in the second (negative) one must
 * not leave the first one's plane written */
SW(openness_both)
{
    hfvis_sweep_options o = sweep_opts(al);
    hfvis_openness_options oo = hfvis_openness_options_default();
    oo.negative = 2;
    return hfvis_openness(&g_ok, 4, &oo, &o, AF(2 * GW * GH), GW);
}
SW(horizon_map) { hfvis_sweep_options o = sweep_opts(al); return hfvis_horizon_map(&g_ok, 4, &o, AF(4 * GW * GH)); }
/* exact rays: the same calls through the exact-mode paths */
static hfvis_sweep_options exact_opts(const hfvis_allocator *al)
{
    hfvis_sweep_options o = sweep_opts(al);
    o.rays = HFVIS_RAYS_EXACT;
    return o;
}
SW(sweep_azimuths) { hfvis_sweep_options o = exact_opts(al); return hfvis_sweep_azimuths(8, &o, AD(8), AD(8)); }
SW(horizon_exact_naive) { hfvis_sweep_options o = exact_opts(al); return hfvis_horizon_exact_naive(&g_ok, 8, &o, AF(8 * GW * GH)); }
SW(horizon_map_exact) { hfvis_sweep_options o = exact_opts(al); return hfvis_horizon_map(&g_ok, 8, &o, AF(8 * GW * GH)); }
SW(horizon_direction_exact) { hfvis_sweep_options o = exact_opts(al); return hfvis_horizon_direction(&g_ok, 8, 3, &o, AF(GW * GH), GW); }
SW(sky_light_exact) { hfvis_sweep_options o = exact_opts(al); return hfvis_sky_light(&g_ok, 8, 1.0f, 1.0f, &o, AF(GW * GH), GW); }
SW(sky_view_factor_exact) { hfvis_sweep_options o = exact_opts(al); return hfvis_sky_view_factor(&g_ok, 8, &o, AF(GW * GH), GW); }
SW(sun_visibility_exact) { hfvis_sweep_options o = exact_opts(al); return hfvis_sun_visibility(&g_ok, 0.3, 0.4, 0.01, &o, AF(GW * GH), GW); }
SW(env_light_exact) { hfvis_sweep_options o = exact_opts(al); return hfvis_env_light(&g_ok, 8, &g_env, 1.0f, &o, NULL, AF(GW * GH), GW); }
SW(sky_light) { hfvis_sweep_options o = sweep_opts(al); return hfvis_sky_light(&g_ok, 4, 1.0f, 1.0f, &o, AF(GW * GH), GW); }
SW(sky_light_from_map) { return hfvis_sky_light_from_map(&g_ok, 4, 0.0, g_map, 1.0f, 1.0f, al, AF(GW * GH), GW); }
SW(sky_view_factor) { hfvis_sweep_options o = sweep_opts(al); return hfvis_sky_view_factor(&g_ok, 4, &o, AF(GW * GH), GW); }
SW(sun_visibility) { hfvis_sweep_options o = sweep_opts(al); return hfvis_sun_visibility(&g_ok, 0.3, 0.4, 0.01, &o, AF(GW * GH), GW); }
SW(env_light) { hfvis_sweep_options o = sweep_opts(al); return hfvis_env_light(&g_ok, 4, &g_env, 1.0f, &o, NULL, AF(GW * GH), GW); }
SW(env_light_from_map) { return hfvis_env_light_from_map(&g_ok, 4, 0.0, g_map, &g_env, 1.0f, NULL, al, AF(GW * GH), GW); }
SW(intervisibility)
{
    hfvis_sweep_options o = sweep_opts(al);
    int calls = 0;
    hfvis_visibility_stats *st = AT(hfvis_visibility_stats);
    return hfvis_intervisibility(&g_ok, 4, &o, NULL, vis_cb, &calls, st);
}
SW(visibility_count)
{
    hfvis_sweep_options o = sweep_opts(al);
    float *out = AF(GW * GH);
    return hfvis_visibility_count(&g_ok, 4, &o, NULL, out, GW, AT(hfvis_visibility_stats));
}
SW(visibility_count_naive)
{
    hfvis_sweep_options o = sweep_opts(al);
    float *out = AF(GW * GH);
    return hfvis_visibility_count_naive(&g_ok, 4, &o, out, GW, AT(hfvis_visibility_stats));
}
SW(indirect_light) { hfvis_sweep_options o = sweep_opts(al); return hfvis_indirect_light(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, &o, NULL, AF(GW * GH), GW); }
SW(indirect_light_naive) { hfvis_sweep_options o = sweep_opts(al); return hfvis_indirect_light_naive(&g_ok, 4, ex_rad, 1, 1.0f, 0.5f, &o, AF(GW * GH), GW); }
SW(terrain_gi) { hfvis_sweep_options o = sweep_opts(al); return hfvis_terrain_gi(&g_ok, 4, ex_rad, NULL, NULL, 0.5f, 1, 1, &o, NULL, AF(GW * GH)); }
SW(direct_light)
{
    hfvis_sweep_options o = sweep_opts(al);
    hfvis_sun sun;
    memset(&sun, 0, sizeof sun);
    sun.azimuth_rad = 0.3; sun.elevation_rad = 0.5; sun.radius_rad = 0.01; sun.irradiance[0] = 1.0f;
    return hfvis_direct_light(&g_ok, 4, &sun, 1.0f, &g_env, 1, &o, AF(GW * GH));
}
SW(solar_irradiation)
{
    hfvis_sweep_options o = sweep_opts(al);
    hfvis_solar_options so = hfvis_solar_options_default();
    hfvis_solar_input in = solar_in_ok();
    hfvis_solar_output out;
    memset(&out, 0, sizeof out);
    out.global = AF(GW * GH);
    so.sweep = &o;
    so.directions = 8;
    so.diffuse = HFVIS_SOLAR_DIFFUSE_HORIZON;
    so.reflected = HFVIS_SOLAR_REFLECTED_TERRAIN;
    return hfvis_solar_irradiation(&g_ok, &in, &so, &out);
}
SW(solar_irradiation_window) /* a window of sites by the site function: the blocks' list grows */
{
    hfvis_sweep_options o = sweep_opts(al);
    hfvis_solar_options so = hfvis_solar_options_default();
    hfvis_solar_input in = solar_in_ok();
    hfvis_solar_output out;
    memset(&out, 0, sizeof out);
    out.global = AF(GW * GH);
    o.max_distance = 3.0;
    o.origin_x = 2;
    o.extent_width = GW + 2;
    o.extent_height = GH;
    o.receiver_x = 1;
    o.receiver_width = 2;
    o.receiver_height = GH;
    in.site = solar_site_fn;
    so.sweep = &o;
    so.directions = 8;
    so.site_tolerance_rad = 1e-4; /* a block per cell */
    so.height_min = -1.0;
    so.height_max = 30.0;
    return hfvis_solar_irradiation(&g_ok, &in, &so, &out);
}
SW(solar_map_directions)
{
    hfvis_sweep_options o = sweep_opts(al);
    hfvis_solar_options so = hfvis_solar_options_default();
    hfvis_solar_input in = solar_in_ok();
    so.sweep = &o;
    so.directions = 8;
    return hfvis_solar_map_directions(&g_ok, &in, &so, (unsigned char *)(void *)AF(2));
}
SW(solar_irradiation_reference)
{
    hfvis_sweep_options o = sweep_opts(al);
    hfvis_solar_options so = hfvis_solar_options_default();
    hfvis_solar_input in = solar_in_ok();
    hfvis_solar_output out;
    memset(&out, 0, sizeof out);
    out.global = AF(GW * GH);
    so.sweep = &o;
    so.directions = 8;
    so.diffuse = HFVIS_SOLAR_DIFFUSE_HORIZON;
    so.reflected = HFVIS_SOLAR_REFLECTED_TERRAIN;
    return hfvis_solar_irradiation_reference(&g_ok, &in, &so, &out);
}
SW(ns_gi)
{
    hfvis_ns_scene sc = ns_scene_ok();
    hfvis_ns_gi_options o = hfvis_ns_gi_options_default();
    hfvis_ns_gi_outputs out;
    o.directions = 4; o.alloc = al;
    memset(&out, 0, sizeof out);
    out.bounces = 1; out.total = AF(GW * GH); out.bounce = AF(GW * GH);
    return hfvis_ns_gi(&g_ok, &sc, &o, &out);
}
SW(direction_sums)
{
    hfvis_sweep_options o = sweep_opts(al);
    return hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_SKY_VIEW, NULL, NULL, &o, AD(GW * GH));
}
SW(partial_decode)
{
    hfvis_partial *p = AT(hfvis_partial);
    hfvis_status s = hfvis_partial_decode(p_file, p_file_len, al, p);
    if (s == HFVIS_OK) hfvis_partial_free(al, p);
    return s;
}
SW(partial_load)
{
    hfvis_partial *p = AT(hfvis_partial);
    hfvis_status s = hfvis_partial_load(tmp_path("s.hfvs"), al, p);
    if (s == HFVIS_OK) hfvis_partial_free(al, p);
    return s;
}
SW(lsao_direction)
{
    hfvis_lsao_options o = hfvis_lsao_options_default();
    float *v = AF(lat_ok.sample_count);
    o.alloc = al;
    return hfvis_lsao_direction(&cam_ok, cam_depth, NULL, &o, &lat_ok, lines_ok, v, AF(lat_ok.sample_count));
}
SW(lsao_direction_naive)
{
    hfvis_lsao_options o = hfvis_lsao_options_default();
    float *v = AF(lat_ok.sample_count);
    o.alloc = al;
    return hfvis_lsao_direction_naive(&cam_ok, cam_depth, NULL, &o, &lat_ok, lines_ok, v, AF(lat_ok.sample_count));
}
SW(lsao) { hfvis_lsao_options o = hfvis_lsao_options_default(); o.alloc = al; return hfvis_lsao(&cam_ok, cam_depth, NULL, &o, AF(INNER * INNER), INNER); }
SW(hbao) { hfvis_hbao_options o = hfvis_hbao_options_default(); o.alloc = al; return hfvis_hbao(&cam_ok, cam_depth, NULL, &o, AF(INNER * INNER), INNER); }
SW(ssao_reference)
{
    hfvis_ssao_rt_options o = hfvis_ssao_rt_options_default();
    o.alloc = al; o.rays = 4;
    return hfvis_ssao_reference(&cam_ok, cam_depth, NULL, &o, AF(INNER * INNER), INNER);
}
SW(ffao_table_build)
{
    hfvis_falloff f;
    hfvis_ffao_table *t = AT(hfvis_ffao_table);
    hfvis_status s;
    memset(&f, 0, sizeof f);
    s = hfvis_ffao_table_build(&f, 2, 2, 2, 2, 1.0, al, t);
    if (s == HFVIS_OK) hfvis_ffao_table_free(t);
    return s;
}
SW(ffao) { hfvis_ffao_options o = hfvis_ffao_options_default(); o.alloc = al; return hfvis_ffao(&cam_ok, cam_depth, NULL, &o, AF(INNER * INNER), INNER); }
SW(ssao_mipmap)
{
    hfvis_ffao_options o = hfvis_ffao_options_default();
    o.alloc = al; o.falloff.kind = HFVIS_FALLOFF_STEP; o.falloff.param = 1.0; /* builds the L table per call */
    return hfvis_ssao_mipmap(&cam_ok, cam_depth, NULL, &o, AF(INNER * INNER), INNER);
}

#define SW_MESH(name, call) SW(name) { hfvis_mesh *m = AT(hfvis_mesh); hfvis_status s = (call); \
    if (s == HFVIS_OK) { hfvis_mesh_free(al, m); } \
    return s; }
static const double box_lo[3] = {0, 0, 0}, box_hi[3] = {1, 2, 3};
SW_MESH(mesh_box, hfvis_mesh_box(al, box_lo, box_hi, m))
SW_MESH(mesh_uv_sphere, hfvis_mesh_uv_sphere(al, c_ok, 1.0, 4, 3, m))
SW_MESH(mesh_icosphere, hfvis_mesh_icosphere(al, c_ok, 1.0, 1, m))
SW_MESH(mesh_torus, hfvis_mesh_torus(al, c_ok, 2.0, 0.5, 3, 3, m))
SW_MESH(mesh_torus_knot, hfvis_mesh_torus_knot(al, c_ok, 1.0, 2, 3, 8, 3, m))
SW_MESH(mesh_from_grid, hfvis_mesh_from_grid(al, &g_ok, m))
SW_MESH(mesh_room, hfvis_mesh_room(al, m))
SW_MESH(mesh_teapot, hfvis_mesh_teapot(al, 1, m))
SW_MESH(obj_decode, hfvis_obj_decode(obj_ok, sizeof obj_ok - 1, al, m))
SW_MESH(mesh_load, hfvis_mesh_load(tmp_path("a.obj"), al, m))

SW(rasterize)
{
    hfvis_raster_options o = hfvis_raster_options_default();
    hfvis_raster_outputs out = raster_outputs();
    o.alloc = al;
    return hfvis_rasterize(&m_box, &view_ok, &o, &out);
}
SW(bvh_build)
{
    hfvis_bvh_options o = hfvis_bvh_options_default();
    hfvis_bvh *b = AT(hfvis_bvh);
    hfvis_status s;
    o.alloc = al;
    s = hfvis_bvh_build(&m_box, &o, b);
    if (s == HFVIS_OK) hfvis_bvh_free(al, b);
    return s;
}
SW(voxelize_conservative)
{
    hfvis_binary_voxel_options o = hfvis_binary_voxel_options_default();
    uint8_t *occ = ATN(uint8_t, 64);
    o.alloc = al;
    return hfvis_voxelize_conservative(&m_box, &vg_ok, &o, occ, AT(size_t));
}
SW(voxelize_solid)
{
    hfvis_binary_voxel_options o = hfvis_binary_voxel_options_default();
    uint8_t *occ = ATN(uint8_t, 64);
    o.alloc = al;
    return hfvis_voxelize_solid(&m_box, &vg_ok, &o, occ, AT(size_t));
}
SW(mesh_is_watertight) { return hfvis_mesh_is_watertight(&m_box, al, AT(int)); }
SW(binvox_decode)
{
    hfvis_volume_grid *g = AT(hfvis_volume_grid);
    uint8_t **occ = AT(uint8_t *);
    hfvis_status s = hfvis_binvox_decode(binvox_buf, binvox_len, al, g, occ);
    if (s == HFVIS_OK) hfvis_free(al, *occ);
    return s;
}
SW(binvox_load)
{
    hfvis_volume_grid *g = AT(hfvis_volume_grid);
    uint8_t **occ = AT(uint8_t *);
    hfvis_status s = hfvis_binvox_load(tmp_path("s.binvox"), al, g, occ);
    if (s == HFVIS_OK) hfvis_free(al, *occ);
    return s;
}

/* The IV passes allocate only with the conservative footprint. */
static hfvis_iv_options iv_cons(const hfvis_allocator *al)
{
    hfvis_iv_options o = hfvis_iv_options_default();
    o.footprint = HFVIS_IV_FOOTPRINT_CONSERVATIVE; o.alloc = al;
    return o;
}
SW(iv_cleanup)
{
    hfvis_iv_options o = iv_cons(al);
    hfvis_volume prev = iv_prev(), cur = arena_volume(2);
    return hfvis_iv_cleanup(&prev, &cur, &iv_img, 1, &o, AT(hfvis_iv_stats));
}
SW(iv_update)
{
    hfvis_iv_options o = iv_cons(al);
    hfvis_volume prev = iv_prev(), cur = arena_volume(2);
    return hfvis_iv_update(&prev, &cur, &iv_img, 1, &o, AT(hfvis_iv_stats));
}
SW(iv_single_pass)
{
    hfvis_iv_options o = iv_cons(al);
    hfvis_volume prev = iv_prev(), cur = arena_volume(2);
    return hfvis_iv_single_pass(&prev, &cur, &iv_img, 1, &o, AT(hfvis_iv_stats));
}
SW(voxel_distance_metrics)
{
    hfvis_distance_options o;
    memset(&o, 0, sizeof o);
    o.sample_count = 64; o.alloc = al;
    return hfvis_voxel_distance_metrics(&m_box, &vg_ok, occ_box, &o, AT(hfvis_distance_metrics));
}
SW(voxel_distance_metrics_naive)
{
    hfvis_distance_options o;
    memset(&o, 0, sizeof o);
    o.sample_count = 64; o.alloc = al;
    return hfvis_voxel_distance_metrics_naive(&m_box, &vg_ok, occ_box, &o, AT(hfvis_distance_metrics));
}
SW(visfield_build)
{
    hfvis_visfield_build_options o;
    hfvis_visfield v = arena_field();
    memset(&o, 0, sizeof o);
    o.alloc = al;
    return hfvis_visfield_build(&m_box, &o, &v);
}
SW(visfield_ambient_occlusion)
{
    hfvis_visfield_ao_options o = hfvis_visfield_ao_options_default();
    o.rays_sqrt = 2; o.alloc = al;
    return hfvis_visfield_ambient_occlusion(&vf_obj, 1, vp_pts, vp_nrm, 1, &o, AF(1));
}
SW(visfield_ambient_occlusion_reference)
{
    hfvis_visfield_ao_options o = hfvis_visfield_ao_options_default();
    o.rays_sqrt = 2; o.alloc = al;
    return hfvis_visfield_ambient_occlusion_reference(&vf_obj, 1, vp_pts, vp_nrm, 1, &o, AF(1));
}
SW(visfield_soft_shadow)
{
    hfvis_visfield_shadow_options o;
    memset(&o, 0, sizeof o);
    o.samples = 4; o.alloc = al;
    return hfvis_visfield_soft_shadow(&vf_obj, 1, vp_pts, 1, light_c, 0.5, &o, AF(1));
}
SW(visfield_soft_shadow_reference)
{
    hfvis_visfield_shadow_options o;
    memset(&o, 0, sizeof o);
    o.samples = 4; o.alloc = al;
    return hfvis_visfield_soft_shadow_reference(&vf_obj, 1, vp_pts, 1, light_c, 0.5, &o, AF(1));
}
SW(visfield_decode)
{
    hfvis_visfield *v = AT(hfvis_visfield);
    hfvis_status s = hfvis_visfield_decode(vf_file, vf_file_len, al, v);
    if (s == HFVIS_OK) hfvis_visfield_free(al, v);
    return s;
}
SW(visfield_load)
{
    hfvis_visfield *v = AT(hfvis_visfield);
    hfvis_status s = hfvis_visfield_load(tmp_path("s.hfvf"), al, v);
    if (s == HFVIS_OK) hfvis_visfield_free(al, v);
    return s;
}
SW(volgi_propagate_step)
{
    hfvis_volgi_options o;
    float *pout = AF(27 * 12), *acc = AF(27 * 12);
    memset(&o, 0, sizeof o);
    o.alloc = al; o.transfer = HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED;
    return hfvis_volgi_propagate_step(&geo_ok, &o, sh_prop, pout, acc, AT(hfvis_volgi_energy));
}
SW(volgi_propagate)
{
    hfvis_volgi_options o;
    float *prop = AF(27 * 12), *acc = AF(27 * 12);
    memset(&o, 0, sizeof o);
    o.alloc = al;
    return hfvis_volgi_propagate(&geo_ok, &o, 2, prop, acc, NULL);
}
SW(volgi_voxelize)
{
    hfvis_volgi_scene sc = scene_ok();
    hfvis_volgi_options o;
    float *occ = AF(64), *nrm = AF(192), *rad = AF(192);
    memset(&o, 0, sizeof o);
    o.alloc = al;
    sc.bvh = NULL; /* builds its own */
    return hfvis_volgi_voxelize(&sc, &vg_ok, &o, occ, nrm, NULL, rad, NULL);
}
SW(volgi_render)
{
    hfvis_volgi_scene sc = scene_ok();
    hfvis_volgi_options o;
    hfvis_volgi_outputs out;
    memset(&o, 0, sizeof o);
    o.alloc = al; o.iterations = 2; o.resolution = 4;
    sc.bvh = NULL;
    out.direct = AF(192); out.indirect = AF(192); out.total = AF(192);
    return hfvis_volgi_render(&sc, NULL, &view_ok, &o, &out, AT(hfvis_volgi_render_info));
}
SW(lk_rays_build)
{
    hfvis_lk_ray_options o = hfvis_lk_ray_options_default();
    hfvis_lk_rays *r = AT(hfvis_lk_rays);
    hfvis_status s;
    o.alloc = al; o.lloyd_iterations = 1; o.final_iterations = 1; o.density_resolution = 16;
    s = hfvis_lk_rays_build(8, 1.0, &o, r);
    if (s == HFVIS_OK) hfvis_lk_rays_free(al, r);
    return s;
}
SW(lk_rays_custom)
{
    hfvis_lk_rays *r = AT(hfvis_lk_rays);
    hfvis_status s = hfvis_lk_rays_custom(2, 1.0, lk_dirs, lk_len, al, r);
    if (s == HFVIS_OK) hfvis_lk_rays_free(al, r);
    return s;
}
SW(lk_lut_build)
{
    hfvis_lk_rays r; /* an input: not in the arena */
    hfvis_lk_lut *l = AT(hfvis_lk_lut);
    hfvis_status s;
    /* variable lengths: two tables, so both allocations are swept */
    if (hfvis_lk_rays_custom(2, 1.0, lk_dirs, lk_len, NULL, &r) != HFVIS_OK) return HFVIS_ERR_INVALID_ARGUMENT;
    s = hfvis_lk_lut_build(&r, 4, al, l);
    if (s == HFVIS_OK) hfvis_lk_lut_free(al, l);
    hfvis_lk_rays_free(NULL, &r);
    return s;
}
SW(lk_gbuffer_receivers)
{
    hfvis_lk_options o = hfvis_lk_options_default();
    double *pos = AD(3 * 64), *nrm = AD(3 * 64);
    o.alloc = al;
    return hfvis_lk_gbuffer_receivers(&m_box, &view_ok, &o, pos, nrm, NULL, AT(size_t));
}
SW(lk_raster)
{
    hfvis_lk_options o = hfvis_lk_options_default();
    uint32_t *masks = ATN(uint32_t, 64);
    o.alloc = al;
    return hfvis_lk_raster(&m_box, &view_ok, &lk_rays, &o, masks, AF(64), NULL);
}
SW(lk_bvh)
{
    hfvis_lk_options o = hfvis_lk_options_default();
    hfvis_lk_receivers rc = recv_ok();
    uint32_t *masks = ATN(uint32_t, 2);
    o.alloc = al;
    return hfvis_lk_bvh(&m_box, &m_bvh, &lk_rays, &rc, &o, masks, AF(2), NULL);
}
SW(lk_reference)
{
    hfvis_lk_options o = hfvis_lk_options_default();
    hfvis_lk_receivers rc = recv_ok();
    uint32_t *masks = ATN(uint32_t, 2);
    o.alloc = al;
    return hfvis_lk_reference(&m_box, &m_bvh, &lk_rays, &rc, &o, masks, AF(2), NULL);
}
SW(lk_image)
{
    hfvis_lk_options o = hfvis_lk_options_default();
    uint32_t *masks = ATN(uint32_t, 64);
    o.alloc = al;
    return hfvis_lk_image(HFVIS_LK_METHOD_BVH, &m_box, NULL, &view_ok, &lk_rays, &o, masks, AF(64), NULL);
}

/* Functions that take an allocator (argument or options) but are documented to allocate
 * nothing for these inputs: the sweep checks they make no call at all. */
SW(horizon_reference)
{
    static const float pts[2] = {1.0f, 1.0f};
    hfvis_sweep_options o = sweep_opts(al);
    return hfvis_horizon_reference(&g_ok, 4, &o, NULL, pts, 1, AF(4));
}
SW(horizon_reference_fn)
{
    static const float pts[2] = {1.0f, 1.0f};
    hfvis_sweep_options o = sweep_opts(al);
    return hfvis_horizon_reference_fn(plane_fn, NULL, GW, GH, 1.0, 4, &o, NULL, pts, 1, AF(4));
}
SW(light_reference)
{
    static const float pts[2] = {1.0f, 1.0f}, nrm[3] = {0.0f, 0.0f, 1.0f};
    hfvis_sweep_options o = sweep_opts(al);
    hfvis_hemisphere_options h;
    h.azimuth_samples = 4; h.zenith_samples = 4;
    return hfvis_light_reference(&g_ok, NULL, 1.0f, &o, NULL, &h, pts, nrm, 1, AF(1));
}
SW(viewshed)
{
    hfvis_viewshed_options o;
    memset(&o, 0, sizeof o);
    o.alloc = al;
    return hfvis_viewshed(&g_ok, 1.0, 1.0, &o, AF(GW * GH), GW);
}
SW(viewshed_reference)
{
    hfvis_viewshed_options o;
    memset(&o, 0, sizeof o);
    o.alloc = al;
    return hfvis_viewshed_reference(&g_ok, 1.0, 1.0, &o, 0.5, AF(GW * GH), GW);
}
SW(lsao_gather)
{
    hfvis_lsao_options o = hfvis_lsao_options_default();
    double *sum = AD(INNER * INNER);
    o.alloc = al;
    return hfvis_lsao_gather(&cam_ok, cam_depth, NULL, &o, &lat_ok, lines_ok, lat_vals, lat_sd, sum, AD(INNER * INNER));
}
SW(rasterize_reference)
{
    hfvis_raster_options o = hfvis_raster_options_default();
    hfvis_raster_outputs out = raster_outputs();
    o.alloc = al;
    return hfvis_rasterize_reference(&m_box, &view_ok, &o, &out);
}
SW(voxelize_surface)
{
    hfvis_voxelize_options o = hfvis_voxelize_options_default();
    hfvis_volume v = arena_volume(1);
    o.alloc = al;
    return hfvis_voxelize_surface(&m_box, &v, &o, NULL);
}
SW(voxelize_conservative_reference)
{
    hfvis_binary_voxel_options o = hfvis_binary_voxel_options_default();
    uint8_t *occ = ATN(uint8_t, 64);
    o.alloc = al;
    return hfvis_voxelize_conservative_reference(&m_box, &vg_ok, &o, occ, NULL);
}
SW(voxelize_solid_reference)
{
    hfvis_binary_voxel_options o = hfvis_binary_voxel_options_default();
    uint8_t *occ = ATN(uint8_t, 64);
    o.alloc = al;
    return hfvis_voxelize_solid_reference(&m_box, &vg_ok, &o, occ, NULL);
}
SW(voxelize_bitmask)
{
    hfvis_binary_voxel_options o = hfvis_binary_voxel_options_default();
    uint32_t *bits = ATN(uint32_t, 16);
    o.alloc = al;
    return hfvis_voxelize_bitmask(&m_box, &vg_ok, &o, bits, NULL);
}
SW(iv_inject)
{
    hfvis_iv_options o = iv_cons(al);
    hfvis_volume cur = arena_volume(2);
    return hfvis_iv_inject(&cur, &iv_img, 1, &o, NULL);
}
SW(visfield_build_reference)
{
    hfvis_visfield_build_options o;
    hfvis_visfield v = arena_field();
    memset(&o, 0, sizeof o);
    o.alloc = al;
    return hfvis_visfield_build_reference(&m_box, &o, &v);
}
SW(volgi_propagate_step_reference)
{
    hfvis_volgi_options o;
    float *pout = AF(27 * 12), *acc = AF(27 * 12);
    memset(&o, 0, sizeof o);
    o.alloc = al; o.transfer = HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED;
    return hfvis_volgi_propagate_step_reference(&geo_ok, &o, sh_prop, pout, acc, NULL);
}
SW(volgi_direct_irradiance)
{
    static const double p[3] = {0.5, 0.5, 1.0}, n[3] = {0, 0, 1};
    hfvis_volgi_scene sc = scene_ok();
    hfvis_volgi_options o;
    memset(&o, 0, sizeof o);
    o.alloc = al;
    return hfvis_volgi_direct_irradiance(&sc, &o, p, n, HFVIS_NO_TRIANGLE, AF(3));
}
SW(volgi_gather)
{
    hfvis_volgi_options o;
    memset(&o, 0, sizeof o);
    o.alloc = al;
    return hfvis_volgi_gather(&geo_ok, sh_accum, &o, gp, gn, AF(3));
}

/* Variants that take other allocation paths of the same functions. */
SW(ffao_sparse_blur)
{
    hfvis_ffao_options o = hfvis_ffao_options_default();
    o.alloc = al; o.directions = 9; o.sparse = 1; o.blur = 1;
    return hfvis_ffao(&cam_ok, cam_depth, NULL, &o, AF(INNER * INNER), INNER);
}
SW(volgi_propagate_normalized)
{
    hfvis_volgi_options o;
    float *prop = AF(27 * 12), *acc = AF(27 * 12);
    memset(&o, 0, sizeof o);
    o.alloc = al; o.transfer = HFVIS_VOLGI_TRANSFER_CONE_NORMALIZED;
    return hfvis_volgi_propagate(&geo_ok, &o, 2, prop, acc, ATN(hfvis_volgi_energy, 2));
}
SW(direction_sums_env_range)
{
    hfvis_sweep_options o = sweep_opts(al);
    hfvis_env_options e = hfvis_env_options_default();
    e.method = HFVIS_ENV_LP_TABLE;
    o.direction_begin = 1; o.direction_end = 3; o.direction_order = HFVIS_DIRECTION_ORDER_SWEEP;
    return hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_ENV_LIGHT, &g_env, &e, &o, AD(GW * GH));
}
SW(direction_sums_visibility)
{
    hfvis_sweep_options o = sweep_opts(al);
    return hfvis_direction_sums(&g_ok, 4, HFVIS_SUM_VISIBILITY, NULL, NULL, &o, AD(GW * GH));
}
SW(lk_image_raster)
{
    hfvis_lk_options o = hfvis_lk_options_default();
    uint32_t *masks = ATN(uint32_t, 64);
    o.alloc = al;
    return hfvis_lk_image(HFVIS_LK_METHOD_RASTER, &m_box, NULL, &view_ok, &lk_rays, &o, masks, AF(64), NULL);
}
SW(lk_image_raycast)
{
    hfvis_lk_options o = hfvis_lk_options_default();
    o.alloc = al;
    return hfvis_lk_image(HFVIS_LK_METHOD_RAYCAST, &m_box, NULL, &view_ok, &lk_rays, &o, NULL, AF(64), NULL);
}
SW(lk_raster_lut)
{
    hfvis_lk_options o = hfvis_lk_options_default();
    o.alloc = al; o.mask_mode = HFVIS_LK_MASK_LUT; o.lut = &lut_ok;
    return hfvis_lk_raster(&m_box, &view_ok, &lk_rays, &o, NULL, AF(64), NULL);
}
SW(iv_cleanup_two_images)
{
    hfvis_iv_options o = iv_cons(al);
    hfvis_depth_image two[2];
    hfvis_volume prev = iv_prev(), cur = arena_volume(2);
    two[0] = iv_img; two[1] = iv_img;
    return hfvis_iv_cleanup(&prev, &cur, two, 2, &o, NULL);
}
SW(ns_gi_bounces_key_glossy)
{
    static hfvis_sun key;
    hfvis_ns_scene sc = ns_scene_ok();
    hfvis_ns_gi_options o = hfvis_ns_gi_options_default();
    hfvis_ns_gi_outputs out;
    memset(&key, 0, sizeof key);
    key.azimuth_rad = 0.5; key.elevation_rad = 0.7; key.radius_rad = 0.3; key.irradiance[0] = 1.0f;
    sc.lights = &key; sc.light_count = 1; sc.specular = 0.5f; sc.shininess = 8.0f;
    o.directions = 4; o.alloc = al;
    memset(&out, 0, sizeof out);
    out.bounces = 2; out.total = AF(GW * GH); out.visibility = AF(16 * GW * GH);
    return hfvis_ns_gi(&g_ok, &sc, &o, &out);
}
SW(lsao_bilinear_real)
{
    hfvis_lsao_options o = hfvis_lsao_options_default();
    o.alloc = al; o.gather = HFVIS_SSAO_GATHER_BILINEAR; o.tangent = HFVIS_SSAO_TANGENT_REAL;
    o.sampling = HFVIS_SSAO_SAMPLING_BILINEAR;
    return hfvis_lsao(&cam_ok, cam_depth, NULL, &o, AF(INNER * INNER), INNER);
}
SW(volgi_render_grid_bvh)
{
    hfvis_volgi_scene sc = scene_ok();
    hfvis_volgi_options o;
    hfvis_volgi_outputs out;
    memset(&o, 0, sizeof o);
    o.alloc = al; o.iterations = 2;
    out.direct = NULL; out.indirect = AF(192); out.total = NULL;
    return hfvis_volgi_render(&sc, &vg_ok, &view_ok, &o, &out, NULL);
}

typedef struct sweep_entry {
    const char *name;
    hfvis_status (*fn)(const hfvis_allocator *alloc);
    int allocates; /* 1: swept; 0: takes an allocator but must make no call */
} sweep_entry;
#define SWEEP(name) {#name, sw_##name, 1}
#define SWEEP_VARIANT(name, variant) {#name, sw_##variant, 1}
#define NOALLOC(name) {#name, sw_##name, 0}

static const sweep_entry sweeps[] = {
    SWEEP(image_load), SWEEP(horizon_lattice), SWEEP(horizon_lattice_naive), SWEEP(horizon_direction),
    SWEEP(openness), SWEEP_VARIANT(openness, openness_both),
    SWEEP(horizon_map), SWEEP(sky_light), SWEEP(sky_light_from_map), SWEEP(sky_view_factor),
    SWEEP(sweep_azimuths), SWEEP(horizon_exact_naive), SWEEP_VARIANT(horizon_map, horizon_map_exact),
    SWEEP_VARIANT(horizon_direction, horizon_direction_exact), SWEEP_VARIANT(sky_light, sky_light_exact),
    SWEEP_VARIANT(sky_view_factor, sky_view_factor_exact), SWEEP_VARIANT(sun_visibility, sun_visibility_exact),
    SWEEP_VARIANT(env_light, env_light_exact),
    SWEEP(sun_visibility), SWEEP(env_light), SWEEP(env_light_from_map), SWEEP(intervisibility),
    SWEEP(visibility_count), SWEEP(visibility_count_naive), SWEEP(indirect_light),
    SWEEP(indirect_light_naive), SWEEP(terrain_gi), SWEEP(direct_light), SWEEP(solar_irradiation), SWEEP_VARIANT(solar_irradiation, solar_irradiation_window), SWEEP(solar_map_directions), SWEEP(solar_irradiation_reference), SWEEP(ns_gi),
    SWEEP(direction_sums), SWEEP(partial_decode), SWEEP(partial_load),
    SWEEP(lsao_direction), SWEEP(lsao_direction_naive), SWEEP(lsao), SWEEP(hbao), SWEEP(ssao_reference),
    SWEEP(ffao_table_build), SWEEP(ffao), SWEEP(ssao_mipmap),
    SWEEP(mesh_box), SWEEP(mesh_uv_sphere), SWEEP(mesh_icosphere), SWEEP(mesh_torus),
    SWEEP(mesh_torus_knot), SWEEP(mesh_from_grid), SWEEP(mesh_room), SWEEP(mesh_teapot),
    SWEEP(obj_decode), SWEEP(mesh_load), SWEEP(rasterize), SWEEP(bvh_build),
    SWEEP(voxelize_conservative), SWEEP(voxelize_solid), SWEEP(mesh_is_watertight),
    SWEEP(binvox_decode), SWEEP(binvox_load), SWEEP(iv_cleanup), SWEEP(iv_update),
    SWEEP(iv_single_pass), SWEEP(voxel_distance_metrics), SWEEP(voxel_distance_metrics_naive),
    SWEEP(visfield_build), SWEEP(visfield_ambient_occlusion), SWEEP(visfield_ambient_occlusion_reference),
    SWEEP(visfield_soft_shadow), SWEEP(visfield_soft_shadow_reference), SWEEP(visfield_decode),
    SWEEP(visfield_load), SWEEP(volgi_propagate_step), SWEEP(volgi_propagate), SWEEP(volgi_voxelize),
    SWEEP(volgi_render), SWEEP(lk_rays_build), SWEEP(lk_rays_custom), SWEEP(lk_lut_build),
    SWEEP(lk_gbuffer_receivers), SWEEP(lk_raster), SWEEP(lk_bvh), SWEEP(lk_reference), SWEEP(lk_image),
    SWEEP_VARIANT(ffao, ffao_sparse_blur), SWEEP_VARIANT(volgi_propagate, volgi_propagate_normalized),
    SWEEP_VARIANT(lk_image, lk_image_raster), SWEEP_VARIANT(lk_image, lk_image_raycast),
    SWEEP_VARIANT(lk_raster, lk_raster_lut), SWEEP_VARIANT(iv_cleanup, iv_cleanup_two_images),
    SWEEP_VARIANT(ns_gi, ns_gi_bounces_key_glossy), SWEEP_VARIANT(lsao, lsao_bilinear_real),
    SWEEP_VARIANT(volgi_render, volgi_render_grid_bvh),
    SWEEP_VARIANT(direction_sums, direction_sums_env_range),
    SWEEP_VARIANT(direction_sums, direction_sums_visibility),
    NOALLOC(horizon_reference), NOALLOC(horizon_reference_fn), NOALLOC(light_reference),
    NOALLOC(viewshed), NOALLOC(viewshed_reference), NOALLOC(lsao_gather), NOALLOC(rasterize_reference),
    NOALLOC(voxelize_surface), NOALLOC(voxelize_conservative_reference), NOALLOC(voxelize_solid_reference),
    NOALLOC(voxelize_bitmask), NOALLOC(iv_inject), NOALLOC(visfield_build_reference),
    NOALLOC(volgi_propagate_step_reference), NOALLOC(volgi_direct_irradiance), NOALLOC(volgi_gather),
};
#define SWEEP_COUNT ((int)(sizeof sweeps / sizeof sweeps[0]))

/* Largest k tried: far above any function's allocation count (the most, volgi_render without
 * a scene BVH, makes 10). */
#define SWEEP_MAX_K 1000

static int sweep_failures_total; /* failing calls made by the sweep */

/* Fails allocation k = 1, 2, ... until the call succeeds: every failing call must return
 * HFVIS_ERR_OUT_OF_MEMORY, free what it allocated and leave its outputs untouched. Returns the
 * number of allocations of the successful call. */
static long sweep_one(const sweep_entry *e)
{
    test_counting c;
    hfvis_allocator a;
    hfvis_status s;
    long k, calls;
    begin(e->name);
    a = test_counting_allocator(&c, 0);
    s = e->fn(&a);
    calls = c.allocs;
    CHECK_EQ_STATUS(s, HFVIS_OK);
    CHECK(c.live == 0);
    if (e->allocates ? calls == 0 : calls != 0) {
        CHECK(0);
        fprintf(stderr, "  (%s: %ld allocations, inventory says it %s)\n", e->name, calls,
                e->allocates ? "allocates" : "allocates nothing");
    }
    for (k = 1; k <= SWEEP_MAX_K; k++) {
        arena_used = 0;
        arena_fill_upto(arena_high + ARENA_SLACK);
        a = test_counting_allocator(&c, k);
        s = e->fn(&a);
        if (c.allocs < k) { /* allocation k never happened: the call ran to completion */
            CHECK_EQ_STATUS(s, HFVIS_OK);
            CHECK(c.live == 0);
            break;
        }
        sweep_failures_total++;
        CHECK_EQ_STATUS(s, HFVIS_ERR_OUT_OF_MEMORY);
        CHECK(c.live == 0);
        CHECK(arena_untouched());
        if (s != HFVIS_ERR_OUT_OF_MEMORY || c.live != 0 || !arena_untouched())
            fprintf(stderr, "  (%s: failing allocation %ld of %ld)\n", e->name, k, calls);
    }
    CHECK(k <= SWEEP_MAX_K);
    return calls;
}

/* ---- allocator-less functions (the *_save writers): their I/O failure paths in a temp dir -- */

static hfvis_status io_pfm_save(const char *path)
{
    static const float px[2] = {1.0f, 2.0f};
    return hfvis_pfm_save(path, px, 2, 1, 1, 2);
}
static hfvis_status io_pgm_save(const char *path)
{
    static const float px[2] = {1.0f, 2.0f};
    return hfvis_pgm_save(path, px, 2, 1, 2, 0.0f, 2.0f, 255);
}
static hfvis_status io_pgm_range_save(const char *path)
{
    static const float px[2] = {1.0f, (float)NAN};
    return hfvis_pgm_range_save(path, px, 2, 1, 2, 0.0f, 2.0f);
}
static hfvis_status io_mesh_save(const char *path) { return hfvis_mesh_save(path, &m_box); }
static hfvis_status io_binvox_save(const char *path) { return hfvis_binvox_save(path, &vg_ok, occ_box); }
static hfvis_status io_voxels_raw_save(const char *path) { return hfvis_voxels_raw_save(path, &vg_ok, occ_box); }
static hfvis_status io_visfield_save(const char *path) { return hfvis_visfield_save(path, &vf_ok); }
static hfvis_status io_partial_save(const char *path) { return hfvis_partial_save(path, &p_ok); }
static hfvis_status io_write_file(const char *path) { return hfvis_write_file(path, "abc", 3, NULL); }
static hfvis_status io_write_begin(const char *path)
{
    FILE *f;
    char *tmp;
    hfvis_status s = hfvis_write_begin(path, NULL, &f, &tmp);
    if (s != HFVIS_OK) return s;
    fputs("abc", f);
    return hfvis_write_end(path, f, tmp, 1, NULL);
}

typedef struct io_entry {
    const char *name;
    hfvis_status (*fn)(const char *path);
} io_entry;
#define IOSAVE(name) {#name, io_##name}
static const io_entry io_savers[] = {
    IOSAVE(pfm_save), IOSAVE(pgm_save), IOSAVE(pgm_range_save), IOSAVE(mesh_save), IOSAVE(binvox_save),
    IOSAVE(voxels_raw_save), IOSAVE(visfield_save), IOSAVE(partial_save), IOSAVE(write_file),
    IOSAVE(write_begin),
};
#define IO_COUNT ((int)(sizeof io_savers / sizeof io_savers[0]))

/* Success writes the file; a path in a missing directory and a path that is a directory fail
 * with HFVIS_ERR_IO and leave no temporary file behind; an existing file is replaced whole. */
static void io_one(const io_entry *e)
{
    char sub[160], target[200];
    FILE *f;
    int before;
    begin(e->name);
    snprintf(sub, sizeof sub, "%s/io_%s", tmpdir, e->name);
    CHECK(mkdir(sub, 0700) == 0);
    snprintf(target, sizeof target, "%s/out", sub);
    CHECK_EQ_STATUS(e->fn(target), HFVIS_OK);
    CHECK((f = fopen(target, "rb")) != NULL);
    if (f) fclose(f);
    before = test_dir_entries(sub);
    snprintf(target, sizeof target, "%s/missing/out", sub);
    CHECK_EQ_STATUS(e->fn(target), HFVIS_ERR_IO);
    CHECK_EQ_STATUS(e->fn(sub), HFVIS_ERR_IO);
    CHECK(test_dir_entries(sub) == before);
    CHECK_EQ_STATUS(e->fn(tmp_path(e->name)), HFVIS_OK);
    CHECK_EQ_STATUS(e->fn(tmp_path(e->name)), HFVIS_OK); /* replaces */
}

/* The option defaults added with 0.2.0: each returns the values its header comment documents
 * (the equality of zero-initialised and default options on a call is test_api's). */
static void args_write_options_default(void)
{
    hfvis_write_options o = hfvis_write_options_default();
    begin("write_options_default");
    CHECK(o.on_temp == NULL && o.user == NULL);
}

static void args_march_options_default(void)
{
    hfvis_march_options o = hfvis_march_options_default();
    begin("march_options_default");
    CHECK(o.step_cells == 1.0 && o.max_distance_cells == 0.0);
}

static void args_openness_options_default(void)
{
    hfvis_openness_options o = hfvis_openness_options_default();
    begin("openness_options_default");
    CHECK(o.radius == 0.0 && o.negative == 0 && o.step_cells == 1.0);
}

static void args_hemisphere_options_default(void)
{
    hfvis_hemisphere_options o = hfvis_hemisphere_options_default();
    begin("hemisphere_options_default");
    CHECK(o.azimuth_samples == 256 && o.zenith_samples == 512);
}

static void args_tree_options_default(void)
{
    hfvis_tree_options o = hfvis_tree_options_default();
    begin("tree_options_default");
    CHECK(o.order == HFVIS_TREE_DEPTH_FIRST && o.safe_zone == 0 && o.safe_zone_steps == 4);
}

static void args_viewshed_options_default(void)
{
    hfvis_viewshed_options o = hfvis_viewshed_options_default();
    begin("viewshed_options_default");
    CHECK(o.observer_height == 0.0 && o.target_height == 0.0 && o.max_distance == 0.0 && o.alloc == NULL);
}

static void args_distance_options_default(void)
{
    hfvis_distance_options o = hfvis_distance_options_default();
    begin("distance_options_default");
    CHECK(o.sample_count == 100000 && o.seed == 0 && o.alloc == NULL);
}

static void args_visfield_build_options_default(void)
{
    hfvis_visfield_build_options o = hfvis_visfield_build_options_default();
    begin("visfield_build_options_default");
    CHECK(o.alloc == NULL && o.bvh == NULL && o.progress == NULL && o.progress_user == NULL);
}

static void args_visfield_shadow_options_default(void)
{
    hfvis_visfield_shadow_options o = hfvis_visfield_shadow_options_default();
    begin("visfield_shadow_options_default");
    CHECK(o.samples == 20 && o.bias == HFVIS_VISFIELD_DEFAULT_BIAS && o.alloc == NULL);
}

static void args_visfield_reflect_options_default(void)
{
    hfvis_visfield_reflect_options o = hfvis_visfield_reflect_options_default();
    begin("visfield_reflect_options_default");
    CHECK(o.rays == 4 && o.shininess == 0.0 && o.bias == HFVIS_VISFIELD_DEFAULT_BIAS && o.offset == 0.0);
}

/* ========================================================================================== */
/* The tests                                                                                  */
/* ========================================================================================== */

typedef struct inv_row {
    const char *name, *kind, *alloc, *classes, *returns;
    void (*fn)(void);   /* the library function (proves the row names a real symbol) */
    void (*args)(void); /* its argument sweep */
} inv_row;
#define X_ROW(name, kind, alloc, classes, returns) \
    {#name, #kind, #alloc, classes, returns, (void (*)(void))hfvis_##name, args_##name},
static const inv_row inventory[] = {HFVIS_INVENTORY(X_ROW)};
#define INVENTORY_COUNT ((int)(sizeof inventory / sizeof inventory[0]))
#define CLASS_LETTERS "NZGOFESR"

static const char *const status_names[] = {"OK", "INVALID_ARGUMENT", "OUT_OF_MEMORY", "FORMAT",
                                           "LIMIT", "BUFFER_TOO_SMALL", "IO"};

/* The same set of letters (order free). */
static int same_classes(const char *a, const char *b)
{
    const char *p;
    for (p = a; *p; p++)
        if (!strchr(b, *p)) return 0;
    for (p = b; *p; p++)
        if (!strchr(a, *p)) return 0;
    return 1;
}

static const inv_row *find_row(const char *name)
{
    int i;
    for (i = 0; i < INVENTORY_COUNT; i++)
        if (strcmp(inventory[i].name, name) == 0) return &inventory[i];
    return NULL;
}

TEST(every_function_every_invalid_class)
{
    int i, c, kinds[3] = {0, 0, 0};
    for (i = 0; i < INVENTORY_COUNT; i++) {
        const inv_row *r = &inventory[i];
        char want[96];
        unsigned s;
        r->args();
        CHECK(r->fn != NULL);
        /* the classes exercised are exactly those the inventory declares */
        CHECK(same_classes(cur_seen, r->classes));
        if (!same_classes(cur_seen, r->classes))
            fprintf(stderr, "  (%s: exercised \"%s\", inventory \"%s\")\n", r->name, cur_seen, r->classes);
        /* S rows: the statuses expected are exactly the documented ones the row lists */
        want[0] = '\0';
        for (s = 1; s < sizeof status_names / sizeof status_names[0]; s++)
            if (cur_status_mask & (1u << s)) {
                if (want[0]) strcat(want, " ");
                strcat(want, status_names[s]);
            }
        kinds[r->kind[0] == 'S' ? 0 : r->kind[0] == 'V' ? 1 : 2]++;
        if (strcmp(r->kind, "S") == 0) {
            CHECK(strcmp(want, r->returns) == 0);
            if (strcmp(want, r->returns) != 0) fprintf(stderr, "  (%s: statuses \"%s\")\n", r->name, want);
        } else if (strcmp(r->kind, "V") == 0) {
            CHECK(cur_status_mask == 0 && cur_value_cases > 0);
        } else {
            CHECK(strcmp(r->kind, "P") == 0 && cur_status_mask == 0 && cur_value_cases == 0 && r->classes[0] == '\0');
        }
    }
    printf("arguments: %d functions (%d status, %d value or no-op, %d cannot fail), %d classes, %d cases:",
           INVENTORY_COUNT, kinds[0], kinds[1], kinds[2], (int)strlen(CLASS_LETTERS), total_cases);
    for (c = 0; CLASS_LETTERS[c]; c++) printf(" %c %d", CLASS_LETTERS[c], class_cases[(unsigned char)CLASS_LETTERS[c]]);
    printf("\n");
}

TEST(inventory_is_the_header)
{
    FILE *f = fopen("hfvis.h", "r");
    char line[512];
    int found = 0, i;
    if (!f) {
        printf("skip: hfvis.h not in the working directory (run from the repository root)\n");
        return;
    }
    while (fgets(line, sizeof line, f)) {
        const char *p, *q;
        char name[128];
        if (strncmp(line, "HFVIS_API ", 10) != 0) continue;
        /* the function name is the identifier before the first '(' */
        if (!(q = strchr(line, '('))) continue;
        for (p = q; p > line && (p[-1] == '_' || (p[-1] >= 'a' && p[-1] <= 'z') || (p[-1] >= '0' && p[-1] <= '9')); p--) {}
        CHECK(strncmp(p, "hfvis_", 6) == 0);
        p += 6;
        if ((size_t)(q - p) >= sizeof name) continue;
        memcpy(name, p, (size_t)(q - p));
        name[q - p] = '\0';
        found++;
        CHECK(find_row(name) != NULL);
        if (!find_row(name)) fprintf(stderr, "  (hfvis_%s is missing from the inventory)\n", name);
    }
    fclose(f);
    CHECK(found == INVENTORY_COUNT);
    for (i = 0; i < INVENTORY_COUNT; i++)
        CHECK(strchr("SVP", inventory[i].kind[0]) && strchr("AM-", inventory[i].alloc[0]));
    printf("inventory: %d HFVIS_API declarations in hfvis.h, %d inventory rows\n", found, INVENTORY_COUNT);
}

TEST(failing_allocator_sweep)
{
    int i, swept = 0, zero = 0, allocating = 0, variants = 0;
    long allocs = 0;
    /* every A row has a sweep; every sweep names a row of the matching kind */
    for (i = 0; i < INVENTORY_COUNT; i++) {
        int j, has = 0;
        for (j = 0; j < SWEEP_COUNT; j++)
            if (strcmp(sweeps[j].name, inventory[i].name) == 0) has = sweeps[j].allocates ? 1 : 2;
        if (inventory[i].alloc[0] == 'A') {
            allocating++;
            CHECK(has == 1);
            if (has != 1) fprintf(stderr, "  (%s allocates but has no sweep)\n", inventory[i].name);
        } else {
            CHECK(has != 1);
        }
    }
    for (i = 0; i < SWEEP_COUNT; i++) {
        const inv_row *r = find_row(sweeps[i].name);
        int j, first = 1;
        CHECK(r != NULL && (r->alloc[0] == 'A') == (sweeps[i].allocates != 0));
        allocs += sweep_one(&sweeps[i]);
        for (j = 0; j < i; j++)
            if (strcmp(sweeps[j].name, sweeps[i].name) == 0) first = 0;
        if (!first) variants++;
        else if (sweeps[i].allocates) swept++;
        else zero++;
    }
    printf("allocator sweep: %d of %d allocating functions swept, %d variant calls (%ld allocations, "
           "%d failing calls); %d more take an allocator and make no call\n", swept, allocating, variants,
           allocs, sweep_failures_total, zero);
    CHECK(swept == allocating);
}

TEST(malloc_only_writers)
{
    int i, rows = 0;
    for (i = 0; i < INVENTORY_COUNT; i++) {
        int j, has = 0;
        for (j = 0; j < IO_COUNT; j++)
            if (strcmp(io_savers[j].name, inventory[i].name) == 0) has = 1;
        CHECK(has == (inventory[i].alloc[0] == 'M'));
        rows += inventory[i].alloc[0] == 'M';
    }
    for (i = 0; i < IO_COUNT; i++) io_one(&io_savers[i]);
    printf("allocator-less writers: %d of %d checked (missing directory, directory as path, replace)\n", IO_COUNT, rows);
}

/* Removes the temporary directory (one level of subdirectories). */
static void remove_tree(const char *dir)
{
    DIR *d = opendir(dir);
    struct dirent *e;
    char p[400];
    if (!d) return;
    while ((e = readdir(d)) != NULL) {
        if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0) continue;
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        if (remove(p) != 0) remove_tree(p);
    }
    closedir(d);
    rmdir(dir);
}

int main(int argc, char **argv)
{
    char t[] = "/tmp/hfvis_args_XXXXXX";
    int rc;
    TEST_INIT(argc, argv);
    arena = (unsigned char *)malloc(ARENA_BYTES);
    arena_expect = (unsigned char *)malloc(ARENA_BYTES);
    if (!arena || !arena_expect || !mkdtemp(t)) return 2;
    snprintf(tmpdir, sizeof tmpdir, "%s", t);
    setup();
    RUN(inventory_is_the_header);
    RUN(every_function_every_invalid_class);
    RUN(failing_allocator_sweep);
    RUN(malloc_only_writers);
    teardown();
    remove_tree(tmpdir);
    free(arena_expect);
    free(arena);
    rc = TEST_DONE();
    return rc;
}
