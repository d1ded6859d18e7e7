#!/bin/sh
# coverage.sh - line coverage of each decoder reached by its fuzz corpus (build/fuzz/corpus_*,
# left by `make fuzz`) plus its seeds: each target is rebuilt with clang source-based coverage,
# replays every input once (libFuzzer -runs=0), and llvm-cov counts the lines of the decoder's
# own functions (the public decode call and the static parsing helpers it uses).
# usage: sh test/fuzz/coverage.sh [TARGET...]   (TARGET: pgm pgm_range pfm obj binvox visfield partial geotiff
# asc ehdr netpbm heightfield; default all)
# heightfield is not a decoder: its lines are the sweep's (lattice, hull, gather, normals, terms).
# Prints "coverage fuzz_T: inputs N, decoder lines covered/total (P%)" per target, then the
# functions with uncovered lines.
CC=${FUZZ_CC:-clang}
for t in "$CC" llvm-profdata llvm-cov; do
  command -v "$t" > /dev/null 2>&1 || { echo "coverage: $t not found"; exit 2; }
done
out=build/fuzz/cov; mkdir -p "$out" || exit 1
img="hfvis_image_info_read hfvis_image_decode hf_img_is_space hf_img_is_digit hf_img_skip hf_img_number hf_img_scale hf_img_p2_samples hf_img_p5_samples hf_img_pfm_rows hf_img_parse hf_img_write_pixels"
# the raster readers of examples/raster_io.h and the inflate of examples/zio.h
tif="ex_rio_open_tiff_mem ex_rio_tiff_parse ex_rio_fetch ex_rio_uint ex_rio_put_uint ex_rio_bits_double ex_rio_bits_float ex_rio_type_size ex_rio_entry_value ex_rio_entry_u ex_rio_entry_doubles ex_rio_entry_fixed ex_rio_entry_chunks ex_rio_compression_name ex_georef_keys ex_georef_transform ex_georef_set_nodata ex_rio_packbits ex_rio_lzw ex_rio_unpredict2 ex_rio_unpredict3 ex_rio_grow ex_rio_chunk ex_rio_sample ex_rio_cell ex_rio_read ex_rio_close ex_inflate ex_inflate_string ex_z_bits ex_z_align ex_z_decode ex_z_build ex_z_codes ex_z_fixed ex_z_dynamic ex_adler32"
targets=${*:-pgm pgm_range pfm obj binvox visfield partial geotiff asc ehdr netpbm heightfield}
for t in $targets; do
  case $t in
    pgm|pfm) fns=$img ;;
    pgm_range) fns="hfvis_pgm_range_read hfvis_pgm_range_decode hf_img_scale" ;;
    obj) fns="hfvis_obj_decode vx_mesh_obj_digit vx_mesh_obj_parse_float vx_mesh_obj_parse_index vx_mesh_obj_space vx_mesh_obj_face_ref vx_mesh_obj_run" ;;
    binvox) fns="hfvis_binvox_decode vx_cons_skip_blank vx_cons_line_end vx_cons_keyword vx_cons_parse_uint vx_cons_parse_field" ;;
    visfield) fns="hfvis_visfield_decode vx_vf_payload_ok vx_vf_get32 vx_vf_get64 vx_vf_getf64 vx_vf_params_ok vx_vf_size64" ;;
    partial) fns="hfvis_partial_decode hf_partial_header hf_partial_number" ;;
    geotiff) fns=$tif ;;
    asc) fns="ex_rio_open_asc_mem ex_rio_parse_asc ex_rio_token ex_rio_keyeq ex_rio_number ex_georef_set_nodata ex_rio_cell ex_rio_read" ;;
    ehdr) fns="ex_rio_open_ehdr_mem ex_rio_parse_hdr ex_rio_token ex_rio_keyeq ex_rio_number ex_georef_set_nodata ex_rio_fetch ex_rio_uint ex_rio_sample ex_rio_cell ex_rio_grow ex_rio_read" ;;
    netpbm) fns="ex_rio_open_netpbm_mem ex_rio_netpbm_parse ex_rio_number ex_rio_fetch ex_rio_uint ex_rio_sample ex_rio_cell ex_rio_grow ex_rio_read" ;;
    heightfield) fns="hf_lattice_from_u hfvis_lattice_line hf_node_inside hf_domain_pad hf_lattice_nodes_bound hf_sweep_group hf_sweep_orientation hf_gather_setup hf_gather_apply hf_gather_elevations hf_gather_planes hf_normal_at hf_sky_term hf_tan_sine hf_svf_term" ;;
    *) echo "coverage: unknown target $t"; exit 2 ;;
  esac
  "$CC" -std=c99 -g -O1 -fsanitize=fuzzer -fprofile-instr-generate -fcoverage-mapping -I. \
    test/fuzz/fuzz_$t.c hfvis.c ssao.c voxel.c -lm -o "$out/fuzz_$t" || exit 1
  rm -f "$out/$t.profraw"
  mkdir -p "build/fuzz/corpus_fuzz_$t"
  n=$(ls "build/fuzz/corpus_fuzz_$t" "test/fuzz/seeds/$t" | grep -vc ':$\|^$')
  LLVM_PROFILE_FILE="$out/$t.profraw" "$out/fuzz_$t" -runs=0 "build/fuzz/corpus_fuzz_$t" "test/fuzz/seeds/$t" \
    > "$out/$t.log" 2>&1 || { cat "$out/$t.log"; exit 1; }
  llvm-profdata merge -sparse "$out/$t.profraw" -o "$out/$t.profdata" || exit 1
  llvm-cov report "$out/fuzz_$t" -instr-profile="$out/$t.profdata" -show-functions hfvis.c voxel.c examples/raster_io.h examples/zio.h \
    > "$out/$t.report" || exit 1
  # Function rows: Name Regions Miss Cover Lines Miss Cover [Branches Miss Cover]; static
  # functions appear as "file.c:name".
  awk -v fns="$fns" -v t="$t" -v n="$n" '
    BEGIN { k = split(fns, f, " "); for (i = 1; i <= k; i++) want[f[i]] = 1 }
    { name = $1; sub(/^.*:/, "", name) }
    (name in want) && NF >= 7 && !(name in seen) { seen[name] = 1; lines += $5; miss += $6
      if ($6 > 0) gaps = gaps sprintf("  %s: %d of %d lines uncovered\n", name, $6, $5) }
    END { printf "coverage fuzz_%s: inputs %d, decoder lines %d/%d (%.1f%%)\n", t, n, lines - miss, lines,
            lines ? 100 * (lines - miss) / lines : 0; printf "%s", gaps
          for (x in want) if (!(x in seen)) printf "  %s: not found in the report\n", x }' "$out/$t.report"
done
