#!/bin/sh
# determinism.sh - hfvis.h, Conventions "Numbers": same input, same binary gives bit-identical output;
# across compilers, outputs agree within a stated tolerance.
# usage: sh test/determinism.sh BUILD_A [BUILD_B]
#   Each BUILD holds a release build (hfvis, examples/, test/imgdiff), e.g. gcc and clang builds
#   made by `make determinism`. Every CLI command below and every example is run twice per build
#   and each output file must be byte-identical (cmp). With BUILD_B, each image of A is compared
#   with B's by imgdiff, which prints the largest absolute and relative difference; other files
#   (.binvox, .raw, .hfvf) must be byte-identical.
# Prints one line per check, then "determinism: N passed, M failed".
a=$1; b=$2
[ -n "$a" ] && [ -x "$a/hfvis" ] && [ -x "$a/test/imgdiff" ] || { echo "usage: sh test/determinism.sh BUILD_A [BUILD_B]"; exit 2; }
[ -z "$b" ] || [ -x "$b/hfvis" ] || { echo "determinism: $b/hfvis missing"; exit 2; }
# Cross-compiler tolerance on every image value: |a - b| <= CROSS_ABS + CROSS_REL*|b|. Both
# builds use -std=c99 -ffp-contract=off (no FMA contraction), SSE2 double arithmetic and the same
# libm, so only a differently ordered sum could move a result: a few float ulps.
CROSS_ABS=1e-6
CROSS_REL=1e-5
# 16-bit PGM outputs quantise v to round(v*65535): a few-ulp change may flip one rounding step.
CROSS_PGM_ABS=1
dir=${TMPDIR:-/tmp}/determinism.$$
rm -rf "$dir"; mkdir -p "$dir/in" || exit 1
passed=0; failed=0
ok()  { passed=$((passed + 1)); echo "ok   $1"; }
bad() { failed=$((failed + 1)); echo "FAIL $1"; }

# ---- inputs (awk only) ---------------------------------------------------------------------
# hill.pgm: 96 x 80 16-bit terrain with ridges and a pit; depth.pgm: 64 x 48 depth buffer (a
# tilted floor with boxes); env.pgm: 16 x 8 sky map brighter at the top; terrain.obj: a 12 x 12
# height-field mesh; cube.obj: the closed unit cube.
awk 'BEGIN { w = 96; h = 80; print "P2"; print w, h; print 65535
  for (y = 0; y < h; y++) { s = ""; for (x = 0; x < w; x++) {
    v = 20000 + 9000 * sin(x / 7) * cos(y / 5) + 6000 * sin((x + y) / 3)
    if ((x - 50) * (x - 50) + (y - 40) * (y - 40) < 60) v = 2000
    s = s " " int(v) } print s } }' > "$dir/in/hill.pgm"
awk 'BEGIN { w = 64; h = 48; print "P2"; print w, h; print 255
  for (y = 0; y < h; y++) { s = ""; for (x = 0; x < w; x++) {
    v = 240 - 2 * y; if (x % 16 < 6 && y % 12 < 5) v -= 40; s = s " " v } print s } }' > "$dir/in/depth.pgm"
awk 'BEGIN { print "P2 16 8 255"; for (y = 0; y < 8; y++) for (x = 0; x < 16; x++) print 255 - 30 * y }' > "$dir/in/env.pgm"
awk 'BEGIN { n = 12
  for (y = 0; y <= n; y++) for (x = 0; x <= n; x++) printf "v %g %g %g\n", x / n, y / n, 0.3 * sin(x / 2) * cos(y / 3)
  for (y = 0; y < n; y++) for (x = 0; x < n; x++) { i = y * (n + 1) + x + 1; printf "f %d %d %d %d\n", i, i + 1, i + n + 2, i + n + 1 } }' > "$dir/in/terrain.obj"
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n' > "$dir/in/cube.obj"

# run_all BUILD OUTDIR: every command writes OUTDIR/<name>.<ext>; the examples write into OUTDIR/ex.
run_all() {
  bd=$1; x=$1/hfvis; o=$2; i=$dir/in
  mkdir -p "$o/ex" || return 1
  set -- \
    "horizon.pfm"     "horizon $i/hill.pgm --dirs 16 --zscale 0.002" \
    "horizon_c.pgm"   "horizon $i/hill.pgm --dirs 7 --compass --degrees --border wrap" \
    "skyview.pfm"     "skyview $i/hill.pgm --zscale 0.002 --border clamp" \
    "sky.pfm"         "sky $i/hill.pgm --zscale 0.002 --sky 2 --albedo 0.5" \
    "shadow.pfm"      "shadow $i/hill.pgm --zscale 0.002 --sun-azimuth 135 --sun-elevation 12 --sun-radius 2" \
    "light.pfm"       "light $i/hill.pgm --zscale 0.002 --env $i/env.pgm" \
    "light_lp.pfm"    "light $i/hill.pgm --zscale 0.002 --env $i/env.pgm --method lp" \
    "normals.pfm"     "normals $i/hill.pgm --zscale 0.002" \
    "indirect.pfm"    "indirect $i/hill.pgm --zscale 0.002 --sun-azimuth 200 --sun-elevation 25 --bounces 2 --dirs 8" \
    "visibility.pfm"  "visibility $i/hill.pgm --zscale 0.002 --dirs 8 --fraction" \
    "viewshed.pfm"    "viewshed $i/hill.pgm --zscale 0.002 --observer 20,30 --observer-height 2" \
    "viewshed_c.pfm"  "viewshed $i/hill.pgm --zscale 0.002 --cell 50 --observer 1000,1500 --observer-height 2 --curvature" \
    "hillshade.pfm"   "hillshade $i/hill.pgm --zscale 0.002 --blend 3 --sun-radius 0.5" \
    "openness.pfm"    "openness $i/hill.pgm --zscale 0.002 --radius 12 --negative" \
    "openness_0.pfm"  "openness $i/hill.pgm --zscale 0.002 --dirs 12" \
    "svf_saga.pfm"    "skyview $i/hill.pgm --zscale 0.002 --svf saga" \
    "gi.pfm"          "gi $i/hill.pgm --zscale 0.002 --sun-azimuth 135 --sun-elevation 30 --specular 0.2 --bounces 2" \
    "ssao_lsao.pfm"   "ssao $i/depth.pgm --method lsao --fov-y 60 --radius 20" \
    "ssao_hbao.pfm"   "ssao $i/depth.pgm --method hbao --fov-y 60 --radius 20" \
    "ssao_ffao.pfm"   "ssao $i/depth.pgm --method ffao --fov-y 60 --radius 20" \
    "ssao_rt.pfm"     "ssao $i/depth.pgm --method raytrace --fov-y 60 --radius 20" \
    "vox_surf.binvox" "voxelize $i/terrain.obj --res 24" \
    "vox_cons.binvox" "voxelize $i/terrain.obj --res 24 --mode conservative" \
    "vox_solid.raw"   "voxelize $i/cube.obj --res 10 --mode solid" \
    "meshao_bvh.pfm"  "meshao $i/terrain.obj --rays 64 --radius 0.4 --size 48x36" \
    "meshao_ras.pfm"  "meshao $i/terrain.obj --method raster --rays 64 --radius 0.4 --size 48x36" \
    "meshao_ray.pfm"  "meshao $i/terrain.obj --method raycast --rays 64 --radius 0.4 --size 48x36" \
    "field.hfvf"      "visfield $i/terrain.obj --positions 82 --dirs 16" \
    "volgi.pfm"       "volgi --room --res 16 --iterations 16 --size 48x36"
  while [ $# -gt 0 ]; do
    # shellcheck disable=SC2086 # the argument string is split on purpose
    "$x" $2 --quiet -o "$o/$1" > /dev/null 2> "$o/$1.err" || { bad "$1: $x failed: $(head -n 1 "$o/$1.err")"; }
    shift 2
  done
  "$x" visfield --ao "$o/field.hfvf" --ground 0 --size 32x32 --rays 4 --quiet -o "$o/field_ao.pfm" > /dev/null 2>&1 \
    || bad "field_ao.pfm: $x failed"
  for e in "$bd"/examples/*; do
    [ -x "$e" ] || continue
    "$e" "$o/ex" > /dev/null 2>&1 || bad "example $(basename "$e") failed"
  done
}

# same_files NAME DIR1 DIR2: every file of DIR1 exists in DIR2 with the same bytes.
same_files() {
  n=0; diff=0
  for f in "$2"/*.* "$2"/ex/*; do
    [ -f "$f" ] || continue
    case $f in *.err) continue ;; esac
    rel=${f#"$2"/}; n=$((n + 1))
    cmp -s "$f" "$3/$rel" || { diff=$((diff + 1)); echo "     differs: $rel"; }
  done
  if [ "$n" -gt 0 ] && [ "$diff" -eq 0 ]; then ok "$1: $n files bit-identical over two runs"
  else bad "$1: $diff of $n files differ between two runs"; fi
}

run_all "$a" "$dir/a1"; run_all "$a" "$dir/a2"
same_files "$a" "$dir/a1" "$dir/a2"
[ -z "$b" ] || { run_all "$b" "$dir/b1"; run_all "$b" "$dir/b2"; same_files "$b" "$dir/b1" "$dir/b2"; }

# ---- across compilers -----------------------------------------------------------------------
if [ -n "$b" ]; then
  for f in "$dir"/a1/*.* "$dir"/a1/ex/*; do
    [ -f "$f" ] || continue
    rel=${f#"$dir"/a1/}
    case $rel in
      *.err) ;;
      *.pfm|*.pgm)
        case $rel in *.pgm) tol_abs=$CROSS_PGM_ABS ;; *) tol_abs=$CROSS_ABS ;; esac
        if line=$("$a/test/imgdiff" "$f" "$dir/b1/$rel" "$tol_abs" "$CROSS_REL"); then ok "$a vs $b $rel: $line"
        else bad "$a vs $b $rel: $line (tolerance $tol_abs + $CROSS_REL rel)"; fi ;;
      *)
        if cmp -s "$f" "$dir/b1/$rel"; then ok "$a vs $b $rel: bit-identical"
        else bad "$a vs $b $rel: $(cmp -l "$f" "$dir/b1/$rel" 2>&1 | wc -l | tr -d ' ') bytes differ"; fi ;;
    esac
  done
fi
rm -rf "$dir"
echo "determinism: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
