#!/bin/sh
# tiles_cli_test.sh - rasters larger than memory through the hfvis tool (docs/tiles.md): --window
# pieces read from .flt, PFM, binary PGM and ASC inputs, 'hfvis mosaic' of uneven windows (edges,
# 1-cell-wide windows, windows larger than the field, clipped) against the whole run bit for bit,
# multi-plane (horizon) and RGB (light) pieces, the mosaic's refusals (different inputs,
# parameters, R, CRS, cell size; overlapping and missing pieces), --window refused without R,
# the memory refusal's suggested window, 'hfvis info' and examples/tiles.sh's tile list.
# The inputs are written here with awk (integer heights: exact as floats), no other tool.
#
# Two kinds of bit-identity checks:
#  - plumbing: windows whose halo covers the whole field (the piece's grid is the whole field),
#    and openness --radius (a ray march that is local by itself): pass with any library;
#  - search radius: a 1024 x 1024 field cut into uneven windows with R = 20 cells; these need the
#    library's max_distance/origin/extent/receiver support (hfvis_sweep_options). A probe checks
#    whether the library honours max_distance (a result equal to the unlimited one fails).
# usage: sh test/tiles_cli_test.sh BUILD/hfvis SCRATCHDIR
hfvis=$1
[ -n "$hfvis" ] && [ -x "$hfvis" ] || { echo "usage: sh test/tiles_cli_test.sh BUILD/hfvis SCRATCHDIR"; exit 2; }
here=$(cd "$(dirname "$0")" && pwd)
dir=${2:-${TMPDIR:-/tmp}}/tiles_cli_test.$$
rm -rf "$dir"; mkdir -p "$dir" || exit 1
passed=0; failed=0
ok()  { passed=$((passed + 1)); echo "ok   tiles $1"; }
bad() { failed=$((failed + 1)); echo "FAIL tiles $1"; }
run() { name=$1; shift; if "$hfvis" "$@" > /dev/null 2> "$dir/err"; then return 0; fi
        bad "$name: exit $?: $(head -n 2 "$dir/err")"; return 1; }
# fails NAME CODE PATTERN ARGS...: exit CODE with exactly one stderr line matching PATTERN
fails() { name=$1; code=$2; pat=$3; shift 3; "$hfvis" "$@" > /dev/null 2> "$dir/err"; rc=$?
          if [ "$rc" -eq "$code" ] && [ "$(wc -l < "$dir/err" | tr -d ' ')" = 1 ] && grep -q -- "$pat" "$dir/err"
          then ok "$name: $(cat "$dir/err")"; else bad "$name: exit $rc, stderr: $(head -n 3 "$dir/err")"; fi; }
same() { if cmp -s "$2" "$3"; then ok "$1"; else bad "$1: $2 and $3 differ"; fi; }

# field W H SEED STEM [ALL]: integer heights (sines, noise, terraces, a one-cell wall, a NoData
# hole of -9999) as STEM.flt + STEM.hdr (cell 2 m, UTM origin) and, unless ALL is 0, STEM.pfm and
# STEM.asc
field() {
  LC_ALL=C awk -v w="$1" -v h="$2" -v seed="$3" -v stem="$4" -v all="${5:-1}" '
  function f32(v,   e, m, b, bits) { # IEEE single of an integer v (|v| < 2^24), little endian
    if (v == 0) { printf "%c%c%c%c", 0, 0, 0, 0 > out; return }
    s = v < 0 ? 128 : 0; if (v < 0) v = -v
    e = 0; while (2 ^ (e + 1) <= v) e++
    m = v * 2 ^ (23 - e) - 2 ^ 23
    bits = (127 + e) * 2 ^ 23 + m
    b0 = bits % 256; bits = int(bits / 256); b1 = bits % 256; bits = int(bits / 256)
    b2 = bits % 256; b3 = int(bits / 256)
    printf "%c%c%c%c", b0, b1, b2, b3 + s > out }
  BEGIN { srand(seed)
    for (y = 0; y < h; y++) for (x = 0; x < w; x++) {
      v = 20000 + int(6000 * sin(x / 37 + seed) * cos(y / 29) + 2500 * sin((x + 2 * y) / 11) + 900 * rand())
      if (x > w / 2 && x < w / 2 + 40) v = int(v / 1500) * 1500      # terraces
      if (x == int(w / 3)) v += 4000                                # a one-cell wall
      if (x >= 10 && x < 13 && y >= 20 && y < 22) v = -9999          # a hole
      z[y * w + x] = v }
    out = stem ".flt"
    for (y = 0; y < h; y++) for (x = 0; x < w; x++) f32(z[y * w + x])
    printf "ncols %d\nnrows %d\nxllcorner 500000\nyllcorner 4100000\ncellsize 2\nNODATA_value -9999\nbyteorder LSBFIRST\n", w, h > stem ".hdr"
    if (!all) exit
    out = stem ".pfm"; printf "Pf\n%d %d\n-1.0\n", w, h > out
    for (y = h - 1; y >= 0; y--) for (x = 0; x < w; x++) f32(z[y * w + x])
    out = stem ".asc"
    printf "ncols %d\nnrows %d\nxllcorner 500000\nyllcorner 4100000\ncellsize 2\nNODATA_value -9999\n", w, h > out
    for (y = 0; y < h; y++) { line = ""; for (x = 0; x < w; x++) line = line " " z[y * w + x]; print line > out } }'
}
prj() { printf 'PROJCS["WGS 84 / UTM zone %sN",GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],PARAMETER["central_meridian",%s],UNIT["metre",1],AUTHORITY["EPSG","326%s"]]\n' "$1" "$2" "$1"; }

# pieces NAME OUTEXT WINDOWS CMD... : one piece per window (windows "x,y,w,h" separated by spaces),
# then the mosaic $dir/NAME.mosaic.OUTEXT; returns 1 after reporting a failing piece
pieces() { pname=$1; pext=$2; wins=$3; shift 3; list=""; i=0
  for win in $wins; do i=$((i + 1))
    run "$pname piece $win" "$@" --window "$win" -o "$dir/$pname.$i.$pext" || return 1
    list="$list $dir/$pname.$i.$pext"; done
  # shellcheck disable=SC2086
  run "$pname mosaic" mosaic $list -o "$dir/$pname.mosaic.$pext"; }

# ---- a 97 x 83 field: plumbing (the halo of R = 400 m at 2 m covers it) ----------------------
field 97 83 7 "$dir/s"
prj 33 15 > "$dir/s.prj"
W1="0,0,40,30 40,0,1,30 41,0,100,30 0,30,97,1 -5,31,50,60 45,31,60,60"   # edges, 1-wide, clipped
for fmt in flt pfm asc; do
  extra=""; [ "$fmt" = pfm ] && extra="--cell 2 --nodata -9999"
  # shellcheck disable=SC2086
  run "skyview whole $fmt" skyview "$dir/s.$fmt" $extra --dirs 8 --max-distance 400 -o "$dir/sv_$fmt.whole.pfm" &&
  pieces "sv_$fmt" pfm "$W1" skyview "$dir/s.$fmt" $extra --dirs 8 --max-distance 400 &&
  same "skyview $fmt: mosaic of 6 uneven windows = whole run (halo covers the field)" "$dir/sv_$fmt.whole.pfm" "$dir/sv_$fmt.mosaic.pfm"
done
same "skyview: .flt, PFM and ASC inputs give one result" "$dir/sv_flt.whole.pfm" "$dir/sv_pfm.whole.pfm"
for mode in lattice exact; do
  ex=""; [ "$mode" = exact ] && ex="--exact"
  for c in skyview sky horizon shadow; do
    args="--dirs 8"; [ "$c" = shadow ] && args="--sun-azimuth 200 --sun-elevation 12"
    # shellcheck disable=SC2086
    run "$c $mode whole" $c "$dir/s.flt" $args $ex --max-distance 400 -o "$dir/$c$mode.whole.tif" &&
    pieces "$c$mode" tif "$W1" $c "$dir/s.flt" $args $ex --max-distance 400 &&
    same "$c $mode: GeoTIFF mosaic = whole run's GeoTIFF (georeference, NoData, planes)" "$dir/$c$mode.whole.tif" "$dir/$c$mode.mosaic.tif"
  done
done
run "horizon whole pfm" horizon "$dir/s.flt" --dirs 4 --max-distance 400 -o "$dir/hz.whole.pfm" &&
pieces hz pfm "$W1" horizon "$dir/s.flt" --dirs 4 --max-distance 400 &&
same "horizon: 4 stacked planes mosaic (PFM) = whole run" "$dir/hz.whole.pfm" "$dir/hz.mosaic.pfm"
run "horizon mosaic as .flt" mosaic "$dir"/hz.[1-6].pfm -o "$dir/hz.mosaic.flt" &&
run "horizon whole .flt" horizon "$dir/s.flt" --dirs 4 --max-distance 400 -o "$dir/hz.whole.flt" &&
same "horizon: PFM pieces mosaic to .flt bands = whole run's .flt" "$dir/hz.whole.flt" "$dir/hz.mosaic.flt"
same "horizon: and its .hdr" "$dir/hz.whole.hdr" "$dir/hz.mosaic.hdr"
run "skyview whole pgm" skyview "$dir/s.flt" --dirs 8 --max-distance 400 -o "$dir/svp.whole.pgm" &&
run "skyview mosaic pgm" mosaic "$dir"/sv_flt.[1-6].pfm -o "$dir/svp.mosaic.pgm" &&
same "skyview: mosaic to .pgm = whole run's .pgm (its default range)" "$dir/svp.whole.pgm" "$dir/svp.mosaic.pgm"
# light with an RGB environment (values 0.5, 1, 2: exact bytes), 3-channel pieces
LC_ALL=C awk 'BEGIN { printf "PF\n8 4\n-1.0\n"; for (i = 0; i < 32; i++) { printf "%c%c%c%c", 0, 0, 0, 63
  printf "%c%c%c%c", 0, 0, 128, 63; printf "%c%c%c%c", 0, 0, 0, 64 } }' > "$dir/env.pfm"
# (the field without its .prj: PFM pieces carry no CRS, so the GeoTIFF mosaic of them has the
# geotransform but no GeoKeys, while a whole run of s.flt gets them from s.prj; docs/tiles.md)
cp "$dir/s.flt" "$dir/n.flt"; cp "$dir/s.hdr" "$dir/n.hdr"
run "light whole" light "$dir/n.flt" --env "$dir/env.pfm" --dirs 8 --max-distance 400 -o "$dir/li.whole.tif" &&
pieces li pfm "$W1" light "$dir/n.flt" --env "$dir/env.pfm" --dirs 8 --max-distance 400 &&
run "light mosaic tif" mosaic "$dir"/li.[1-6].pfm -o "$dir/li.mosaic.tif" &&
same "light: RGB pieces mosaic (3 bands, default range) = whole run" "$dir/li.whole.tif" "$dir/li.mosaic.tif"
# hillshade's cast shadows: sun visibility with the radius, pieces as GeoTIFF
for c in hillshade; do
  args="--sun-azimuth 200 --sun-elevation 12 --blend 2"
  # shellcheck disable=SC2086
  run "$c whole" $c "$dir/s.flt" $args --max-distance 400 -o "$dir/$c.whole.tif" &&
  pieces "$c" tif "$W1" $c "$dir/s.flt" $args --max-distance 400 &&
  same "$c: GeoTIFF mosaic = whole run" "$dir/$c.whole.tif" "$dir/$c.mosaic.tif"
done
# openness --radius: a ray march local by itself, so real halos (4 cells) tile exactly today
run "openness whole" openness "$dir/s.flt" --radius 6 -o "$dir/op.whole.tif" &&
pieces op tif "$W1" openness "$dir/s.flt" --radius 6 &&
same "openness --radius 6 (halo 4 cells): mosaic = whole run" "$dir/op.whole.tif" "$dir/op.mosaic.tif"
# --border clamp: openness windows march a plain grid whose edges are the raster's where a march
# meets them, so clamp tiles exactly; a sweep's clamped lines start outside the whole raster: refused
run "openness clamp whole" openness "$dir/s.flt" --radius 6 --border clamp -o "$dir/opc.whole.tif" &&
pieces opc tif "$W1" openness "$dir/s.flt" --radius 6 --border clamp &&
same "openness --radius 6 --border clamp: mosaic = whole run" "$dir/opc.whole.tif" "$dir/opc.mosaic.tif"
fails "skyview --border clamp --window" 2 "--border clamp" skyview "$dir/s.flt" --max-distance 400 --border clamp --window 0,0,10,10 -o "$dir/x.pfm"
grep -q '^window=40,0,1,30 planes=1 channels=1 range=' "$dir/op.2.tif.tile" && ok "sidecar records the window" || bad "sidecar: $(head -n 2 "$dir/op.2.tif.tile")"
grep -q 'extent=97x83 ' "$dir/op.2.tif.tile" && ok "sidecar records the extent" || bad "sidecar extent"
grep -q 'max-distance=0x1.9p+8 ' "$dir/sv_flt.1.pfm.tile" && ok "sidecar records R" || bad "sidecar R"

# ---- refusals ---------------------------------------------------------------------------------
# the [P2] hull-tree commands honour R but compute no windows: refused with the reason
fails "visibility --window" 2 "computes no windows" visibility "$dir/s.flt" --dirs 8 --max-distance 400 --window 0,0,10,10 -o "$dir/x.tif"
fails "indirect --window" 2 "computes no windows" indirect "$dir/s.flt" --dirs 8 --window 0,0,10,10 -o "$dir/x.tif"
fails "window without R" 2 "needs a finite --max-distance" skyview "$dir/s.flt" --window 0,0,10,10 -o "$dir/x.pfm"
fails "openness window without --radius" 2 "needs a finite --radius" openness "$dir/s.flt" --window 0,0,10,10 -o "$dir/x.pfm"
fails "window outside the raster" 1 "lies outside the raster" skyview "$dir/s.flt" --max-distance 10 --window 97,0,5,5 -o "$dir/x.pfm"
fails "malformed window" 2 "expected X0,Y0,W,H" skyview "$dir/s.flt" --max-distance 10 --window 0,0,0,5 -o "$dir/x.pfm"
fails "PGM piece" 2 "keeps its values" skyview "$dir/s.flt" --max-distance 10 --window 0,0,5,5 -o "$dir/x.pgm"
fails "window with --dir-range" 2 "dir-range" skyview "$dir/s.flt" --max-distance 10 --window 0,0,5,5 --dir-range 0:4 -o "$dir/x.hfvs"
printf 'P2\n3 3\n9\n1 2 3 4 5 6 7 8 9\n' > "$dir/p2.pgm"
fails "window of a P2 PGM" 1 "binary (P5)" skyview "$dir/p2.pgm" --max-distance 10 --window 0,0,5,5 -o "$dir/x.pfm"
fails "window not on viewshed" 2 "--window is not used by viewshed" viewshed "$dir/s.flt" --observer-grid 3,3 --window 0,0,5,5 -o "$dir/x.pfm"
# a second field of the same size, the same field with another CRS, another cell size
field 97 83 8 "$dir/t"
cp "$dir/s.prj" "$dir/t.prj"
cp "$dir/s.flt" "$dir/u.flt"; cp "$dir/s.hdr" "$dir/u.hdr"; prj 34 21 > "$dir/u.prj"
cp "$dir/s.flt" "$dir/c.flt"; sed 's/^cellsize 2$/cellsize 3/' "$dir/s.hdr" > "$dir/c.hdr"; cp "$dir/s.prj" "$dir/c.prj"
A="--dirs 8 --max-distance 400"
# shellcheck disable=SC2086
run "piece t" skyview "$dir/t.flt" $A --window 40,0,57,83 -o "$dir/t2.pfm" &&
run "piece s1" skyview "$dir/s.flt" $A --window 0,0,40,83 -o "$dir/s1.pfm" &&
run "piece s2" skyview "$dir/s.flt" $A --window 40,0,57,83 -o "$dir/s2.pfm" &&
run "piece u2" skyview "$dir/u.flt" $A --window 40,0,57,83 -o "$dir/u2.pfm" &&
run "piece c2" skyview "$dir/c.flt" $A --window 40,0,57,83 -o "$dir/c2.pfm" &&
run "piece k2" skyview "$dir/s.flt" --dirs 16 --max-distance 400 --window 40,0,57,83 -o "$dir/k2.pfm" &&
run "piece r2" skyview "$dir/s.flt" --dirs 8 --max-distance 500 --window 40,0,57,83 -o "$dir/r2.pfm" &&
run "piece o2" skyview "$dir/s.flt" $A --window 39,0,58,83 -o "$dir/o2.pfm" &&
run "piece m2" skyview "$dir/s.flt" $A --window 40,0,57,80 -o "$dir/m2.pfm" &&
run "piece s2 tif" skyview "$dir/s.flt" $A --window 40,0,57,83 -o "$dir/s2.tif" &&
run "piece s1 tif" skyview "$dir/s.flt" $A --window 0,0,40,83 -o "$dir/s1.tif"
run "mosaic s1 s2" mosaic "$dir/s1.pfm" "$dir/s2.pfm" -o "$dir/s12.pfm" && same "two pieces = whole" "$dir/s12.pfm" "$dir/sv_flt.whole.pfm"
fails "mosaic: different inputs" 1 "different inputs" mosaic "$dir/s1.pfm" "$dir/t2.pfm" -o "$dir/x.pfm"
fails "mosaic: different CRS" 1 "different CRS" mosaic "$dir/s1.pfm" "$dir/u2.pfm" -o "$dir/x.pfm"
fails "mosaic: different cell size" 1 "different cell sizes" mosaic "$dir/s1.pfm" "$dir/c2.pfm" -o "$dir/x.pfm"
fails "mosaic: different parameters" 1 "different parameters (dirs=8 there, 16 here)" mosaic "$dir/s1.pfm" "$dir/k2.pfm" -o "$dir/x.pfm"
fails "mosaic: different R" 1 "different R" mosaic "$dir/s1.pfm" "$dir/r2.pfm" -o "$dir/x.pfm"
fails "mosaic: overlapping pieces" 1 "overlaps" mosaic "$dir/s1.pfm" "$dir/o2.pfm" -o "$dir/x.pfm"
fails "mosaic: missing piece" 1 "missing pieces: 4731 of the 97 x 83 cells" mosaic "$dir/s1.pfm" -o "$dir/x.pfm"
fails "mosaic: missing rows" 1 "missing pieces: 171 of" mosaic "$dir/s1.pfm" "$dir/m2.pfm" -o "$dir/x.pfm"
fails "mosaic: no sidecar" 1 "no sidecar" mosaic "$dir/s1.pfm" "$dir/sv_flt.whole.pfm" -o "$dir/x.pfm"
fails "mosaic: onto a piece" 1 "refusing to replace an input" mosaic "$dir/s1.pfm" "$dir/s2.pfm" -o "$dir/s2.pfm"
# pieces against their sidecars: each piece's values carry a checksum in its sidecar and each
# raster piece's own origin must lie where its sidecar's window puts it. Pieces 1 and 2 have the
# same size, so swapping them (or their sidecars) changes nothing but where their data lands.
Q="0,0,32,83 32,0,32,83 64,0,33,83"
pieces q pfm "$Q" skyview "$dir/s.flt" $A && same "3 pieces (PFM) = whole run" "$dir/q.mosaic.pfm" "$dir/sv_flt.whole.pfm"
pieces q tif "$Q" skyview "$dir/s.flt" $A && same "3 pieces (GeoTIFF) = whole run" "$dir/q.mosaic.tif" "$dir/skyviewlattice.whole.tif"
# tampered SET EXT: a copy of the q pieces in $dir/SET
tampered() { rm -rf "${dir:?}/$1"; mkdir "$dir/$1" && cp "$dir"/q.[123].$2 "$dir"/q.[123].$2.tile "$dir/$1/"; }
for e in pfm tif; do
  why="its values differ from those its sidecar"; [ "$e" = tif ] && why="its own origin lies"
  tampered sw $e; mv "$dir/sw/q.1.$e" "$dir/sw/t"; mv "$dir/sw/q.2.$e" "$dir/sw/q.1.$e"; mv "$dir/sw/t" "$dir/sw/q.2.$e"
  fails "mosaic: swapped $e pieces" 1 "$why" mosaic "$dir"/sw/q.[123].$e -o "$dir/x.$e"
  tampered sw $e; mv "$dir/sw/q.1.$e.tile" "$dir/sw/t"; mv "$dir/sw/q.2.$e.tile" "$dir/sw/q.1.$e.tile"; mv "$dir/sw/t" "$dir/sw/q.2.$e.tile"
  fails "mosaic: swapped $e sidecars" 1 "$why" mosaic "$dir"/sw/q.[123].$e -o "$dir/x.$e"
done
tampered ed pfm; printf '\001' | dd of="$dir/ed/q.2.pfm" bs=1 seek=400 conv=notrunc 2> /dev/null
fails "mosaic: an edited pixel" 1 "its values differ from those its sidecar" mosaic "$dir"/ed/q.[123].pfm -o "$dir/x.pfm"
tampered ed pfm; sed 's/^HFVISTILE 2$/HFVISTILE 1/' "$dir/q.2.pfm.tile" > "$dir/ed/q.2.pfm.tile"
fails "mosaic: a version-1 sidecar (no checksum)" 1 "not a piece sidecar" mosaic "$dir"/ed/q.[123].pfm -o "$dir/x.pfm"
# a --dirs 16 run, and its window 2 rerun with --dirs 4 whose piece or sidecar did not land
pieces k pfm "$Q" skyview "$dir/s.flt" --dirs 16 --max-distance 400 &&
run "piece k2 --dirs 4" skyview "$dir/s.flt" --dirs 4 --max-distance 400 --window 32,0,32,83 -o "$dir/k4.pfm"
tampered st pfm; cp "$dir"/k.[123].pfm "$dir"/k.[123].pfm.tile "$dir/st/"; cp "$dir/k4.pfm.tile" "$dir/st/k.2.pfm.tile"
fails "mosaic: a stale --dirs 4 sidecar among --dirs 16 pieces" 1 "different parameters (dirs=16 there, 4 here)" mosaic "$dir"/st/k.[123].pfm -o "$dir/x.pfm"
cp "$dir/k.2.pfm.tile" "$dir/st/k.2.pfm.tile"; cp "$dir/k4.pfm" "$dir/st/k.2.pfm"
fails "mosaic: a --dirs 4 piece under its --dirs 16 sidecar" 1 "its values differ from those its sidecar" mosaic "$dir"/st/k.[123].pfm -o "$dir/x.pfm"
cp "$dir/k.2.pfm" "$dir/st/k.2.pfm"
run "mosaic k restored" mosaic "$dir"/st/k.[123].pfm -o "$dir/k.restored.pfm" && same "the restored pieces mosaic as before" "$dir/k.mosaic.pfm" "$dir/k.restored.pfm"
[ -f "$dir/x.pfm" ] || [ -f "$dir/x.tif" ] && bad "a refused mosaic wrote its output" || ok "refused mosaics wrote nothing"
run "mosaic tif pieces" mosaic "$dir/s1.tif" "$dir/s2.tif" -o "$dir/s12.tif" &&
run "whole tif" skyview "$dir/s.flt" $A -o "$dir/sw.tif" && same "GeoTIFF pieces mosaic = whole GeoTIFF" "$dir/sw.tif" "$dir/s12.tif"

# ---- hfvis sum parts record R: parts of one R add up to the whole run, of two R are refused ----
run "sum part R 400 a" skyview "$dir/s.flt" $A --dir-range 0:4 -o "$dir/pa.hfvs" &&
run "sum part R 400 b" skyview "$dir/s.flt" $A --dir-range 4:8 -o "$dir/pb.hfvs" &&
run "sum part R 500 b" skyview "$dir/s.flt" --dirs 8 --max-distance 500 --dir-range 4:8 -o "$dir/pc.hfvs" &&
run "sum of R 400 parts" sum "$dir/pa.hfvs" "$dir/pb.hfvs" -o "$dir/psum.pfm" &&
same "sum of --dir-range parts with R = whole run with R" "$dir/psum.pfm" "$dir/sv_flt.whole.pfm"
fails "sum: parts of different R" 1 "max-distance=0x1.9p+8 there, 0x1.f4p+8 here" sum "$dir/pa.hfvs" "$dir/pc.hfvs" -o "$dir/x.pfm"

# ---- memory: a refusal suggests a window that fits, and that window runs ----------------------
"$hfvis" skyview "$dir/s.flt" --dirs 8 --max-distance 20 --max-memory 300K -o "$dir/x.pfm" 2> "$dir/err"
side=$(sed -n 's/.*windows of \([0-9]*\) x [0-9]* cells fit.*/\1/p' "$dir/err")
if [ -n "$side" ] && [ "$side" -ge 1 ] && [ "$side" -lt 97 ]; then ok "--max-memory refusal suggests ${side} x ${side} windows: $(cat "$dir/err")"
  run "suggested window fits" skyview "$dir/s.flt" --dirs 8 --max-distance 20 --max-memory 300K --window "30,30,$side,$side" -o "$dir/x.pfm" && ok "the suggested window runs under the same --max-memory"
  rm -f "$dir/x.pfm" "$dir/x.pfm.tile"
  fails "one cell larger does not fit" 1 "over --max-memory" skyview "$dir/s.flt" --dirs 8 --max-distance 20 --max-memory 300K --window "30,30,$((side + 1)),$((side + 1))" -o "$dir/x.pfm"
else bad "--max-memory refusal: $(cat "$dir/err")"; fi

# ---- hfvis info, examples/tiles.sh --------------------------------------------------------------
"$hfvis" info "$dir/s.flt" > "$dir/info" 2>&1
if grep -q '^width 97$' "$dir/info" && grep -q '^height 83$' "$dir/info" && grep -q '^cell 2$' "$dir/info" &&
   grep -q '^crs projected' "$dir/info" && grep -q '^nodata -9999$' "$dir/info"; then ok "info: $(tr '\n' ' ' < "$dir/info")"
else bad "info: $(cat "$dir/info")"; fi
# pieces are placed where their cells lie: on a 2 m raster whose upper-left corner is
# (500000, 4100166), window 40,30 starts 80 m east and 60 m south
run "piece .flt at 40,30" skyview "$dir/s.flt" $A --window 40,30,20,10 -o "$dir/g.flt" &&
"$hfvis" info "$dir/g.flt" > "$dir/info" 2>&1 && grep -q '^origin 500080 4100106$' "$dir/info" &&
grep -q '^width 20$' "$dir/info" && ok "a .flt piece at window 40,30 has its origin 80 m east, 60 m south" || bad "piece origin: $(cat "$dir/info")"
"$hfvis" info "$dir/s2.tif" > "$dir/info" 2>&1 && grep -q '^origin 500080 4100166$' "$dir/info" &&
ok "a GeoTIFF piece at window 40,0 has its origin 80 m east" || bad "GeoTIFF piece origin: $(cat "$dir/info")"
# covers W H: the tile list on stdin tiles [0,W) x [0,H) exactly (inside, disjoint, areas sum)
covers() { awk -F, -v W="$1" -v H="$2" '{ x[NR] = $1; y[NR] = $2; w[NR] = $3; h[NR] = $4; a += $3 * $4
    if ($1 < 0 || $2 < 0 || $3 < 1 || $4 < 1 || $1 + $3 > W || $2 + $4 > H) bad = "outside: " $0 }
  END { for (i = 1; i <= NR; i++) for (j = 1; j < i; j++)
          if (x[i] < x[j] + w[j] && x[j] < x[i] + w[i] && y[i] < y[j] + h[j] && y[j] < y[i] + h[i]) bad = "overlap"
        if (a != W * H) bad = bad " area " a " of " W * H
        if (bad != "") { print bad; exit 1 } }'; }
for args in "400 1G" "20 300K" "20 2M" "1 100K"; do
  # shellcheck disable=SC2086
  if HFVIS="$hfvis" sh "$here/../examples/tiles.sh" "$dir/s.flt" $args > "$dir/tiles" 2> "$dir/err" &&
     [ -s "$dir/tiles" ] && covers 97 83 < "$dir/tiles" > "$dir/cov"; then
    ok "tiles.sh s.flt $args: $(wc -l < "$dir/tiles" | tr -d ' ') tiles cover 97 x 83 exactly"
  else bad "tiles.sh $args: $(cat "$dir/err" "$dir/cov" 2> /dev/null | head -n 3)"; fi
done
HFVIS="$hfvis" sh "$here/../examples/tiles.sh" "$dir/s.flt" 400 17M > "$dir/tiles" 2> /dev/null
[ "$(wc -l < "$dir/tiles" | tr -d ' ')" = 4 ] && ok "tiles.sh: R 400 m and 17 MiB give 2 x 2 tiles" || bad "tiles.sh 400 17M: $(cat "$dir/tiles")"
list=""; i=0
for win in $(cat "$dir/tiles"); do i=$((i + 1))
  run "tiles.sh piece $win under --max-memory 17M" skyview "$dir/s.flt" $A --max-memory 17M --window "$win" -o "$dir/ts.$i.pfm"
  list="$list $dir/ts.$i.pfm"; done
# shellcheck disable=SC2086
run "tiles.sh mosaic" mosaic $list -o "$dir/ts.mosaic.pfm" && same "tiles.sh's tiles mosaic = whole run" "$dir/ts.mosaic.pfm" "$dir/sv_flt.whole.pfm"

# ---- the search radius: 1024 x 1024, R = 20 cells, uneven windows -----------------------------
field 1024 1024 3 "$dir/big" 0
W2="0,0,300,257 300,0,1,257 301,0,723,257 0,257,1024,1 -40,258,500,800 460,258,700,300 460,558,1,466 461,558,600,500"
R=40 # metres: 20 cells of 2 m, halo 21
# probe: does the library honour max_distance? (skyview with R against unlimited)
run "probe R" skyview "$dir/big.flt" --dirs 8 --max-distance $R -o "$dir/probe_r.pfm" &&
run "probe unlimited" skyview "$dir/big.flt" --dirs 8 -o "$dir/probe_inf.pfm"
if cmp -s "$dir/probe_r.pfm" "$dir/probe_inf.pfm"; then
  bad "search radius: R = $R m gives the unlimited result (the library ignores hfvis_sweep_options.max_distance)"
else
  for mode in lattice exact; do
    ex=""; [ "$mode" = exact ] && ex="--exact"
    for c in skyview sky horizon shadow; do
      args="--dirs 8"; [ "$c" = shadow ] && args="--sun-azimuth 200 --sun-elevation 12"
      # shellcheck disable=SC2086
      run "1024 $c $mode whole" $c "$dir/big.flt" $args $ex --max-distance $R -o "$dir/b$c$mode.whole.pfm" &&
      pieces "b$c$mode" pfm "$W2" $c "$dir/big.flt" $args $ex --max-distance $R &&
      same "1024x1024 $c $mode, R = 20 cells: mosaic of 8 uneven windows = whole run" "$dir/b$c$mode.whole.pfm" "$dir/b$c$mode.mosaic.pfm"
      rm -f "$dir"/b$c$mode.*
    done
  done
fi
rm -rf "$dir"
echo "tiles cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
