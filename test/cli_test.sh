#!/bin/sh
# cli_test.sh - end-to-end checks of the hfvis command-line tool (README.md, CLI): every subcommand
# writes its file, closed-form answers on a flat field, and bad input gives a non-zero exit, exactly
# one stderr line "hfvis: ..." and no file left behind.
# usage: sh test/cli_test.sh BUILD/hfvis SCRATCHDIR      (prints one line per check)
hfvis=$1
[ -n "$hfvis" ] && [ -x "$hfvis" ] || { echo "usage: sh test/cli_test.sh BUILD/hfvis SCRATCHDIR"; exit 2; }
dir=${2:-${TMPDIR:-/tmp}}/cli_test.$$
rm -rf "$dir"; mkdir -p "$dir/fail" || exit 1
fdir=$dir/fail          # outputs of failing runs go here; it must stay empty
passed=0; failed=0
ok()  { passed=$((passed + 1)); echo "ok   cli $1"; }
bad() { failed=$((failed + 1)); echo "FAIL cli $1"; }

# ---- inputs, written with printf/awk only -------------------------------------------------
# hill.pgm: 24 x 20 ASCII PGM of a smooth bump pattern; flat.pgm: 8 x 6, all 100.
awk 'BEGIN { w = 24; h = 20; print "P2"; print w, h; print 255
  for (y = 0; y < h; y++) { s = ""; for (x = 0; x < w; x++) s = s " " int(128 + 100 * sin(x / 3) * cos(y / 4)); print s } }' > "$dir/hill.pgm"
awk 'BEGIN { print "P2 8 6 255"; for (i = 0; i < 48; i++) print 100 }' > "$dir/flat.pgm"
# big.pgm: 100 x 100 zeros, only for the horizon size limit (16-bit maxval just to vary).
awk 'BEGIN { print "P2 100 100 65535"; for (i = 0; i < 100; i++) print "0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0" }' > "$dir/big.pgm"
one='\000\000\200\077'  # 1.0f little-endian
# env1.pfm: 4 x 2 grey lat-long map of radiance 1 (the whole sphere); env3.pfm: the same in RGB.
{ printf 'Pf\n4 2\n-1\n'; i=0; while [ $i -lt 8 ]; do printf "$one"; i=$((i + 1)); done; } > "$dir/env1.pfm"
{ printf 'PF\n4 2\n-1\n'; i=0; while [ $i -lt 24 ]; do printf "$one"; i=$((i + 1)); done; } > "$dir/env3.pfm"
{ printf 'Pf\n4 2\n-1\n'; i=0; while [ $i -lt 8 ]; do printf '\346\261\141\177'; i=$((i + 1)); done; } > "$dir/envhuge.pfm"
printf 'hello, I am not an image\n' > "$dir/garbage.pgm"
# Maps of flat.pgm's size (8 x 6) for indirect: alb51.pgm all 51/255 = 0.2; emit1.pfm radiance 1;
# emit3.pfm RGB radiance 1; neg.pfm one value -1; nanrow.pfm NaN at (0, 0) (the first sample
# of the last stored row: PFM rows go bottom to top); flat7.pgm flat.pgm with 7 at (0, 0).
awk 'BEGIN { print "P2 8 6 255"; for (i = 0; i < 48; i++) print 51 }' > "$dir/alb51.pgm"
awk 'BEGIN { print "P2 8 6 255"; print 7; for (i = 1; i < 48; i++) print 100 }' > "$dir/flat7.pgm"
nan='\000\000\300\177'  # quiet NaN, little-endian
mone='\000\000\200\277' # -1.0f little-endian
{ printf 'Pf\n8 6\n-1\n'; i=0; while [ $i -lt 48 ]; do printf "$one"; i=$((i + 1)); done; } > "$dir/emit1.pfm"
{ printf 'PF\n8 6\n-1\n'; i=0; while [ $i -lt 144 ]; do printf "$one"; i=$((i + 1)); done; } > "$dir/emit3.pfm"
{ printf 'Pf\n8 6\n-1\n'; printf "$mone"; i=1; while [ $i -lt 48 ]; do printf "$one"; i=$((i + 1)); done; } > "$dir/neg.pfm"
{ printf 'Pf\n8 6\n-1\n'; i=0; while [ $i -lt 40 ]; do printf "$one"; i=$((i + 1)); done
  printf "$nan"; i=41; while [ $i -lt 48 ]; do printf "$one"; i=$((i + 1)); done; } > "$dir/nanrow.pfm"
{ printf 'Pf\n4 4\n-1\n'; printf "$one$one$one"; } > "$dir/truncated.pfm"

little_endian=0
[ "$(printf '\001\000' | od -An -tu2 | tr -d ' ')" = 1 ] && little_endian=1

# ---- helpers ------------------------------------------------------------------------------
# drop_notes: remove the "hfvis: note: ..." lines (e.g. "no cell size: using 1") from the last
# run's stderr; test/raster_cli_test.sh checks the notes themselves. It sets err_lines (the lines
# left), err_first (the first of them) and err_text (them, newline-separated). Shell built-ins
# only: a check costs one process, the tool's run (the checks are ~3,000 runs).
drop_notes() {
  err_lines=0; err_first=; err_text=; dropped=0
  [ -s "$dir/stderr" ] || return 0
  while IFS= read -r l || [ -n "$l" ]; do
    case "$l" in "hfvis: note: "*) dropped=1; continue ;; esac
    err_lines=$((err_lines + 1)); [ "$err_lines" -eq 1 ] && err_first=$l
    err_text="$err_text$l
"
  done < "$dir/stderr"
  [ "$dropped" -eq 0 ] || printf '%s' "$err_text" > "$dir/stderr"
}
# fail_left: the names left in $fdir (none: empty).
fail_left() {
  left=
  for x in "$fdir"/* "$fdir"/.[!.]* "$fdir"/..?*; do
    if [ -e "$x" ] || [ -L "$x" ]; then left="$left${left:+ }${x##*/}"; fi
  done
}
# expect_ok NAME OUT ARGS...: exit 0, nothing on stderr, OUT written.
expect_ok() {
  name=$1; out=$2; shift 2
  rm -f "$out"
  "$hfvis" "$@" > "$dir/stdout" 2> "$dir/stderr"; rc=$?
  drop_notes
  if [ "$rc" -ne 0 ]; then bad "$name: exit $rc: $(head -n 3 "$dir/stderr")"
  elif [ "$err_lines" -ne 0 ]; then bad "$name: unexpected stderr: $(head -n 3 "$dir/stderr")"
  elif [ ! -s "$out" ]; then bad "$name: $out not written"
  else ok "$name"; fi
}
# expect_fail NAME STATUS ARGS...: exit STATUS (1 error, 2 usage), exactly one stderr line that
# starts with "hfvis: " and says more than that, and nothing created in $fdir (no output, no
# temporary file).
expect_fail() {
  name=$1; want=$2; shift 2
  "$hfvis" "$@" > "$dir/stdout" 2> "$dir/stderr"; rc=$?
  drop_notes
  fail_left
  if [ "$rc" -ne "$want" ]; then bad "$name: exit $rc, want $want: $(head -n 3 "$dir/stderr")"
  elif [ "$err_lines" != 1 ] || [ "${#err_first}" -le 7 ]; then
    bad "$name: want one stderr line, got $err_lines: $(head -n 3 "$dir/stderr")"
  else case "$err_first" in
    "hfvis: "*)
      if [ -n "$left" ]; then bad "$name: left behind in $fdir: $left"; rm -rf "${fdir:?}"/* "$fdir"/.[!.]*
      else ok "$name: $err_first"; fi ;;
    *) bad "$name: stderr line: $(cat "$dir/stderr")" ;;
  esac; fi
}
# last_bytes FILE N: the last N bytes as hex, "00 00 80 3f".
last_bytes() { tail -c "$2" "$1" | od -An -tx1 | tr -s ' \n' '  ' | sed 's/^ *//; s/ *$//'; }
# expect_bytes NAME FILE N WANT...: the last N bytes of FILE equal one of the WANT strings.
expect_bytes() {
  name=$1; file=$2; n=$3; shift 3
  got=$(last_bytes "$file" "$n")
  for w in "$@"; do [ "$got" = "$w" ] && { ok "$name"; return; }; done
  bad "$name: last $n bytes '$got', want '$1'"
}
# expect_last_float NAME FILE WANT TOL: the last float of a little-endian PFM is WANT +- TOL.
expect_last_float() {
  [ "$little_endian" = 1 ] || { ok "$1: skipped (big-endian host)"; return; }
  got=$(tail -c 4 "$2" | od -An -tf4 | tr -d ' ')
  if awk -v g="$got" -v w="$3" -v t="$4" 'BEGIN { d = g - w; if (d < 0) d = -d; exit !(d <= t) }'
  then ok "$1 ($got)"; else bad "$1: got '$got', want $3 +- $4"; fi
}
# expect_floats NAME FILE FROM_END TOL WANT...: the little-endian floats starting FROM_END bytes
# before the end of FILE are the WANTs, each +- TOL ("nan" matches any NaN).
expect_floats() {
  [ "$little_endian" = 1 ] || { ok "$1: skipped (big-endian host)"; return; }
  name=$1; file=$2; from_end=$3; tol=$4; shift 4
  size=$(wc -c < "$file" | tr -d ' ')
  got=$(od -An -v -tf4 -j $((size - from_end)) -N $((4 * $#)) "$file" | tr -s ' \n' '  ' | sed 's/^ *//; s/ *$//')
  if echo "$got" | awk -v want="$*" -v t="$tol" '{ n = split(want, w, " "); if (NF != n) exit 1
       for (i = 1; i <= n; i++) { g = $i
         if (w[i] == "nan") { if (g !~ /nan/) exit 1; continue }
         if (g ~ /nan/) exit 1; d = g - w[i]; if (d < 0) d = -d; if (d > t) exit 1 } }'
  then ok "$name"; else bad "$name: got '$got', want '$*' +- $tol"; fi
}
# expect_stdout NAME LINE: the last run's stdout has exactly this line.
expect_stdout() {
  if grep -qxF "$2" "$dir/stdout"; then ok "$1"; else bad "$1: no line '$2' in: $(cat "$dir/stdout")"; fi
}
expect_line2() { # NAME FILE WANT: the second header line (PFM dimensions)
  got=$(head -n 2 "$2" | tail -n 1)
  if [ "$got" = "$3" ]; then ok "$1"; else bad "$1: header line 2 '$got', want '$3'"; fi
}

# ---- help ---------------------------------------------------------------------------------
if "$hfvis" --help > "$dir/stdout" 2> "$dir/stderr" && grep -q '^usage: hfvis' "$dir/stdout" && [ ! -s "$dir/stderr" ]
then ok "--help"; else bad "--help"; fi
for c in horizon skyview sky shadow light normals indirect visibility viewshed voxelize gi ssao volgi visfield meshao hillshade openness; do
  if "$hfvis" $c --help > "$dir/stdout" 2>&1 && grep -q "^usage: hfvis $c" "$dir/stdout"
  then ok "$c --help"; else bad "$c --help"; fi
done
if "$hfvis" help shadow > "$dir/stdout" 2>&1 && grep -q '^usage: hfvis shadow' "$dir/stdout"
then ok "help shadow"; else bad "help shadow"; fi

# ---- every subcommand succeeds ------------------------------------------------------------
h=$dir/hill.pgm
expect_ok "horizon pfm" "$dir/h.pfm" horizon "$h" --dirs 8 -o "$dir/h.pfm"
expect_line2 "horizon: 8 planes of 24 x 20 stacked" "$dir/h.pfm" "24 160"
expect_ok "horizon pgm --degrees --compass" "$dir/h.pgm" horizon "$h" --dirs 4 --degrees --compass -o "$dir/h.pgm"
expect_ok "horizon --border wrap --azimuth0" "$dir/hw.pfm" horizon "$h" --dirs 3 --border=wrap --azimuth0 0.3 -o "$dir/hw.pfm"
expect_ok "skyview pfm" "$dir/svf.pfm" skyview "$h" --cell 2 --zscale 0.5 -o "$dir/svf.pfm"
expect_ok "skyview pgm --border clamp --border-cells 5" "$dir/svf.pgm" skyview "$h" --border clamp --border-cells 5 -o "$dir/svf.pgm"
expect_ok "sky" "$dir/sky.pfm" sky "$h" --sky 2 --albedo 0.5 --dirs 12 -o "$dir/sky.pfm"
expect_ok "sky pgm --range" "$dir/sky.pgm" sky "$h" --range 0:1.5 -o "$dir/sky.pgm"
expect_ok "shadow" "$dir/sh.pfm" shadow "$h" --sun-azimuth 135 --sun-elevation 20 -o "$dir/sh.pfm"
expect_ok "shadow --convention grid --sun-radius" "$dir/sh2.pgm" shadow "$h" --convention grid --sun-azimuth -45 --sun-elevation 10 --sun-radius 2 -o "$dir/sh2.pgm"
expect_ok "light grey env" "$dir/l1.pfm" light "$h" --env "$dir/env1.pfm" -o "$dir/l1.pfm"
expect_ok "light rgb env lp" "$dir/l3.pfm" light "$h" --env "$dir/env3.pfm" --method lp --albedo 0.7 -o "$dir/l3.pfm"
head -n 1 "$dir/l3.pfm" | grep -q '^PF' && ok "light rgb env writes PF" || bad "light rgb env writes PF"
expect_ok "light pgm" "$dir/l3.pgm" light "$h" --env "$dir/env3.pfm" -o "$dir/l3.pgm"
expect_ok "normals" "$dir/n.pfm" normals "$h" --nodata 228 -o "$dir/n.pfm"
head -n 1 "$dir/n.pfm" | grep -q '^PF' && ok "normals writes PF" || bad "normals writes PF"
expect_ok "normals pgm" "$dir/n.pgm" normals "$h" -o "$dir/n.pgm"
expect_ok "--quiet, -- before IN" "$dir/q.pfm" skyview --quiet -o "$dir/q.pfm" -- "$h"
expect_ok "a PFM input (the tool's own output)" "$dir/svf2.pfm" skyview "$dir/svf.pfm" -o "$dir/svf2.pfm"
expect_ok "indirect, defaults" "$dir/i.pfm" indirect "$h" -o "$dir/i.pfm"
head -n 1 "$dir/i.pfm" | grep -q '^Pf' && ok "indirect grey writes Pf" || bad "indirect grey writes Pf"
expect_ok "indirect, sun and 3 bounces" "$dir/is.pfm" indirect "$h" --sun-azimuth 135 --sun-elevation 20 --sun-radius 0.27 --sun-irradiance 5 --sky 0.2 --albedo 0.6 --bounces 3 --dirs 8 -o "$dir/is.pfm"
expect_ok "indirect --convention grid --output indirect pgm" "$dir/is.pgm" indirect "$h" --convention grid --sun-azimuth 45 --sun-elevation 30 --output indirect --border wrap --dirs 3 -o "$dir/is.pgm"
expect_ok "indirect rgb env" "$dir/ie.pfm" indirect "$h" --env "$dir/env3.pfm" --albedo 0.5 -o "$dir/ie.pfm"
head -n 1 "$dir/ie.pfm" | grep -q '^PF' && ok "indirect rgb env writes PF" || bad "indirect rgb env writes PF"
expect_ok "indirect --albedo-map pgm --emission" "$dir/im.pfm" indirect "$h" --albedo-map "$h" --emission "$dir/svf.pfm" --output direct -o "$dir/im.pfm"
expect_ok "visibility pfm" "$dir/v.pfm" visibility "$h" --dirs 8 -o "$dir/v.pfm"
expect_ok "visibility pgm --fraction --border clamp" "$dir/v.pgm" visibility "$h" --fraction --border clamp -o "$dir/v.pgm"
expect_ok "visibility --stats --fraction" "$dir/vs.pfm" visibility "$h" --stats --fraction --compass -o "$dir/vs.pfm"
grep -q '^iterations per receiver-direction (t_a): ' "$dir/stdout" && grep -q '^visible/tested: 0\.' "$dir/stdout" \
  && ok "visibility --stats prints t_a and visible/tested" || bad "visibility --stats: $(cat "$dir/stdout")"
# --max-distance on the [P2] commands: a count with R never exceeds the unlimited one, R beyond
# the field (24 x 20 cells, cell 1) is the unlimited run byte for byte; --window stays refused
expect_ok "visibility --max-distance 3" "$dir/v3.pfm" visibility "$h" --dirs 8 --max-distance 3 -o "$dir/v3.pfm"
if [ "$little_endian" = 1 ]; then
  # the 24 x 20 floats are the last 1920 bytes of each PFM
  if tail -c 1920 "$dir/v.pfm" | od -An -v -tf4 | tr -s ' ' '\n' | grep -v '^$' > "$dir/v.txt" &&
     tail -c 1920 "$dir/v3.pfm" | od -An -v -tf4 | tr -s ' ' '\n' | grep -v '^$' > "$dir/v3.txt" &&
     [ "$(wc -l < "$dir/v3.txt")" -eq 480 ] &&
     paste "$dir/v3.txt" "$dir/v.txt" | awk 'NF != 2 || $1 > $2 { bad = 1 } $1 < $2 { less = 1 }
                                             END { exit bad || !less }'
  then ok "visibility: R = 3 counts <= unlimited, some fewer"; else bad "visibility: R = 3 counts not <= unlimited"; fi
else ok "visibility R <= unlimited: skipped (big-endian host)"; fi
expect_ok "visibility --max-distance 1000" "$dir/vR.pfm" visibility "$h" --dirs 8 --max-distance 1000 -o "$dir/vR.pfm"
cmp -s "$dir/v.pfm" "$dir/vR.pfm" && ok "visibility: R beyond the field = unlimited, byte for byte" || bad "visibility: R beyond the field differs"
expect_ok "indirect --max-distance 1000" "$dir/iR.pfm" indirect "$h" --max-distance 1000 -o "$dir/iR.pfm"
cmp -s "$dir/i.pfm" "$dir/iR.pfm" && ok "indirect: R beyond the field = unlimited, byte for byte" || bad "indirect: R beyond the field differs"
expect_ok "indirect --max-distance 2.5" "$dir/i25.pfm" indirect "$h" --max-distance 2.5 --bounces 2 -o "$dir/i25.pfm"
expect_fail "visibility --window" 2 visibility "$h" --max-distance 3 --window 0,0,5,5 -o "$fdir/x.pfm"

# ---- closed forms on a flat field, 8 x 6 ---------------------------------------------------
# The last pixel of a PGM file is (7, 5), the south-east corner; of a PFM (rows stored bottom
# to top) (7, 0), the north-east corner. Sun and horizon directions are axis directions, which
# the sweep reproduces exactly.
f=$dir/flat.pgm
expect_ok "skyview flat" "$dir/f.pgm" skyview "$f" --range 0:1 -o "$dir/f.pgm"
expect_bytes "skyview flat = 1" "$dir/f.pgm" 2 "ff ff"
expect_ok "shadow flat, sun up" "$dir/fs.pgm" shadow "$f" --sun-azimuth 270 --sun-elevation 30 -o "$dir/fs.pgm"
expect_bytes "shadow flat, sun up = 1" "$dir/fs.pgm" 2 "ff ff"
expect_ok "shadow flat, sun down" "$dir/fd.pgm" shadow "$f" --sun-azimuth 270 --sun-elevation -10 -o "$dir/fd.pgm"
expect_bytes "shadow flat, sun in the west below the horizon = 0 (code 1)" "$dir/fd.pgm" 2 "00 01"
expect_ok "normals flat" "$dir/fn.pfm" normals "$f" --zscale 3 -o "$dir/fn.pfm"
expect_bytes "normals flat: z = 1" "$dir/fn.pfm" 4 "00 00 80 3f"
# horizon, --dirs 4 --degrees --convention grid: plane 0 looks east, so (6, 0) sees flat ground
# (0 deg) and (7, 0) nothing (-90 deg); by default (compass) plane 0 looks north, off the grid for
# both; with --border clamp the flat ground extends and both see 0 deg.
expect_ok "horizon flat" "$dir/fh.pfm" horizon "$f" --dirs 4 --degrees --convention grid -o "$dir/fh.pfm"
expect_bytes "horizon flat east: 0, -90 deg" "$dir/fh.pfm" 8 "00 00 00 00 00 00 b4 c2" "00 00 00 80 00 00 b4 c2"
expect_ok "horizon flat --compass" "$dir/fc.pfm" horizon "$f" --dirs 4 --degrees --compass -o "$dir/fc.pfm"
expect_bytes "horizon flat --compass north: -90, -90 deg" "$dir/fc.pfm" 8 "00 00 b4 c2 00 00 b4 c2"
expect_ok "horizon flat --border clamp" "$dir/fb.pfm" horizon "$f" --dirs 4 --border clamp --convention grid -o "$dir/fb.pfm"
expect_bytes "horizon flat clamp east: 0, 0" "$dir/fb.pfm" 8 "00 00 00 00 00 00 00 00" \
  "00 00 00 80 00 00 00 00" "00 00 00 00 00 00 00 80" "00 00 00 80 00 00 00 80"
expect_ok "light flat, uniform env" "$dir/fl.pfm" light "$f" --env "$dir/env1.pfm" -o "$dir/fl.pfm"
expect_last_float "light flat under radiance 1 = 1" "$dir/fl.pfm" 1 1e-4
expect_ok "sky flat" "$dir/fk.pfm" sky "$f" --sky 2 --albedo 0.25 -o "$dir/fk.pfm"
expect_last_float "sky flat = albedo * sky" "$dir/fk.pfm" 0.5 1e-4
expect_ok "--nodata makes holes" "$dir/fnd.pfm" skyview "$f" --nodata 100 -o "$dir/fnd.pfm"
expect_bytes "--nodata hole is NaN" "$dir/fnd.pfm" 4 "00 00 c0 7f" "00 00 c0 ff"
# indirect: a flat field sends no light to itself, so any number of bounces gives exactly the
# direct light L_0 = emission + albedo * D, and --output indirect is exactly 0.
expect_ok "indirect flat, 2 bounces" "$dir/fi2.pfm" indirect "$f" --albedo 0.5 --bounces 2 -o "$dir/fi2.pfm"
expect_ok "indirect flat, --output direct" "$dir/fi0.pfm" indirect "$f" --albedo 0.5 --output direct -o "$dir/fi0.pfm"
cmp -s "$dir/fi2.pfm" "$dir/fi0.pfm" && ok "indirect flat: bounces = direct, bit for bit" || bad "indirect flat: bounces differ from direct"
expect_floats "indirect flat under sky 1, albedo 0.5 = 0.5" "$dir/fi2.pfm" 8 1e-4 0.5 0.5
expect_ok "indirect flat, --output indirect" "$dir/fii.pfm" indirect "$f" --bounces 3 --output indirect -o "$dir/fii.pfm"
expect_floats "indirect flat: L_B - L_0 = 0" "$dir/fii.pfm" 16 0 0 0 0 0
expect_ok "indirect flat, zenith sun" "$dir/fz.pfm" indirect "$f" --sky 0 --sun-azimuth 0 --sun-elevation 90 --sun-irradiance 6.2831853 --albedo 0.25 -o "$dir/fz.pfm"
expect_floats "indirect flat, zenith sun: albedo * E/pi = 0.5" "$dir/fz.pfm" 8 1e-4 0.5 0.5
expect_ok "indirect flat, sun 30 deg high, default E = pi" "$dir/f30.pfm" indirect "$f" --sun-azimuth 200 --sun-elevation 30 --albedo 0.5 -o "$dir/f30.pfm"
expect_floats "indirect flat, sun 30 deg: 0.5 * (sin 30 deg + sky 1) = 0.75" "$dir/f30.pfm" 8 1e-4 0.75 0.75
expect_ok "indirect flat, PGM albedo map" "$dir/fa.pfm" indirect "$f" --albedo-map "$dir/alb51.pgm" -o "$dir/fa.pfm"
expect_floats "indirect flat: PGM albedo 51/255 = 0.2" "$dir/fa.pfm" 8 1e-4 0.2 0.2
expect_ok "indirect flat, emission" "$dir/fe.pfm" indirect "$f" --sky 0 --emission "$dir/emit1.pfm" --albedo 0.5 -o "$dir/fe.pfm"
expect_floats "indirect flat: emission 1, no light = 1" "$dir/fe.pfm" 8 1e-6 1 1
expect_ok "indirect flat, RGB emission, grey albedo map" "$dir/fe3.pfm" indirect "$f" --emission "$dir/emit3.pfm" --albedo-map "$dir/alb51.pgm" -o "$dir/fe3.pfm"
expect_floats "indirect flat: RGB 1 + 0.2 * sky 1 = 1.2" "$dir/fe3.pfm" 12 1e-4 1.2 1.2 1.2
expect_ok "indirect, NaN in a map at a hole of IN" "$dir/fh.pfm" indirect "$dir/flat7.pgm" --nodata 7 --emission "$dir/nanrow.pfm" -o "$dir/fh.pfm"
expect_floats "indirect: the hole is NaN, its neighbour is lit" "$dir/fh.pfm" 32 1e-4 nan 2 2 2 2 2 2 2
# visibility: on a flat field every earlier sample of a line is seen. --dirs 1 --convention grid
# looks east: column x of the 8-wide row sees 7 - x samples; --dirs 4: (7-x) + x + (5-y) + y = 12
# everywhere; --dirs 1 (compass, the default) looks north: row y sees y samples (the first stored
# PFM row is y = 5).
expect_ok "visibility flat east" "$dir/fv1.pfm" visibility "$f" --dirs 1 --convention grid -o "$dir/fv1.pfm"
expect_floats "visibility flat east: 7 - x" "$dir/fv1.pfm" 32 0 7 6 5 4 3 2 1 0
# viewshed: an eye on a flat field sees all of it (grazing counts); --max-distance cuts it off.
expect_ok "viewshed flat" "$dir/vsf.pfm" viewshed "$f" --observer 0,0 -o "$dir/vsf.pfm"
expect_floats "viewshed flat: the last row is seen" "$dir/vsf.pfm" 32 0 1 1 1 1 1 1 1 1
expect_ok "viewshed flat, exact oracle" "$dir/vse.pfm" viewshed "$f" --observer 0,0 --exact -o "$dir/vse.pfm"
cmp -s "$dir/vsf.pfm" "$dir/vse.pfm" && ok "viewshed flat: R2 = exact, bit for bit" || bad "viewshed flat: R2 differs from exact"
expect_ok "viewshed --max-distance" "$dir/vsm.pfm" viewshed "$f" --observer 7,0 --max-distance 2 --cell 1 -o "$dir/vsm.pfm"
expect_floats "viewshed --max-distance: NaN beyond 2 cells" "$dir/vsm.pfm" 32 0 nan nan nan nan nan 1 1 1
expect_ok "viewshed hill pgm, eye and target heights" "$dir/vsh.pgm" viewshed "$h" --observer 3.5,2 --observer-height 1.5 --target-height 0.5 -o "$dir/vsh.pgm"
expect_ok "viewshed with a hole" "$dir/vs7.pfm" viewshed "$dir/flat7.pgm" --nodata 7 --observer 7,5 -o "$dir/vs7.pfm"

# gi (Nowrouzezahrai-Snyder): flat ground under a uniform sky returns albedo*sky, no bounce light.
expect_ok "gi flat" "$dir/gif.pfm" gi "$f" --sky 2 --albedo 0.5 --bounces 2 -o "$dir/gif.pfm"
expect_last_float "gi flat under sky 2, albedo 0.5 = 1" "$dir/gif.pfm" 1 1e-4
expect_ok "gi hill, sun, specular, subsample" "$dir/gih.pgm" gi "$h" --sun-azimuth 135 --sun-elevation 30 --specular 0.2 --subsample 2 --order 2 -o "$dir/gih.pgm"

# ssao: a fronto-parallel plane (linear depth 5 everywhere, 20 x 16) is open: AO 0 by every method;
# the output covers the inner 16 x 12 pixels (guard 2).
{ printf 'Pf\n20 16\n-1\n'; i=0; while [ $i -lt 320 ]; do printf '\000\000\240\100'; i=$((i + 1)); done; } > "$dir/plane.pfm"
for m in lsao hbao ffao raytrace; do
  expect_ok "ssao $m" "$dir/ao_$m.pfm" ssao "$dir/plane.pfm" --method $m --fov-y 60 --guard 2 -o "$dir/ao_$m.pfm"
  [ "$(head -c 9 "$dir/ao_$m.pfm" | tr '\n' ' ')" = "Pf 16 12 " ] && ok "ssao $m: inner 16 x 12" || bad "ssao $m size"
  expect_last_float "ssao $m: open plane" "$dir/ao_$m.pfm" 0 1e-4
done
expect_ok "ssao ortho, falloff, pgm" "$dir/ao.pgm" ssao "$dir/plane.pfm" --ortho 0.1 --radius 2 -o "$dir/ao.pgm"

# voxelize: the unit cube (8 vertices, 12 triangles) in a 4^3 grid: solid fills all 64 voxels,
# conservative the 56 that touch a face, surface (pixel-centre rule) one layer per face.
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n' > "$dir/cube.obj"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' > "$dir/tri.obj"
expect_ok "voxelize solid" "$dir/cs.raw" voxelize "$dir/cube.obj" --res 4 --mode solid -o "$dir/cs.raw"
grep -q '4 x 4 x 4 voxels.*, 64 set' "$dir/stdout" && ok "voxelize solid: 64 voxels" || bad "voxelize solid: $(cat "$dir/stdout")"
[ "$(wc -c < "$dir/cs.raw" | tr -d ' ')" = 64 ] && ok "voxelize raw: 64 bytes" || bad "voxelize raw size"
expect_ok "voxelize conservative" "$dir/cc.binvox" voxelize "$dir/cube.obj" --res 4 --mode conservative -o "$dir/cc.binvox"
grep -q ', 56 set' "$dir/stdout" && ok "voxelize conservative: 56 voxels" || bad "voxelize conservative: $(cat "$dir/stdout")"
head -n 1 "$dir/cc.binvox" | grep -q '^#binvox 1' && ok "voxelize binvox header" || bad "voxelize binvox header"
expect_ok "voxelize surface, all axes, slicing" "$dir/cv.binvox" voxelize "$dir/cube.obj" --res 8 --axis all --method slicing --max-vertices 11 --padding 0.1 -o "$dir/cv.binvox"
expect_ok "voxelize solid --axis x --open" "$dir/co.raw" voxelize "$dir/tri.obj" --res 4 --mode solid --axis x --open -o "$dir/co.raw"
# meshao: the cube seen from outside: every method writes the same image
expect_ok "meshao bvh" "$dir/ao_b.pfm" meshao "$dir/cube.obj" --rays 64 --radius 0.5 --size 24x18 -o "$dir/ao_b.pfm"
expect_ok "meshao raster" "$dir/ao_r.pfm" meshao "$dir/cube.obj" --method raster --rays 64 --radius 0.5 --size 24x18 -o "$dir/ao_r.pfm"
expect_ok "meshao raycast" "$dir/ao_c.pfm" meshao "$dir/cube.obj" --method raycast --rays 64 --radius 0.5 --size 24x18 -o "$dir/ao_c.pfm"
cmp -s "$dir/ao_b.pfm" "$dir/ao_r.pfm" && cmp -s "$dir/ao_b.pfm" "$dir/ao_c.pfm" && ok "meshao: three methods, same bytes" || bad "meshao: methods differ"
# --pattern: torus is the default (same bytes), lloyd and random are other ray sets
expect_ok "meshao --pattern torus" "$dir/ao_t.pfm" meshao "$dir/cube.obj" --pattern torus --two-sided --rays 64 --radius 0.3 --eye 0.5,0.5,0.5 --target 0.5,1,0.5 --fov 90 --size 16x16 -o "$dir/ao_t.pfm"
expect_ok "meshao --pattern lloyd" "$dir/ao_l.pfm" meshao "$dir/cube.obj" --pattern lloyd --two-sided --rays 64 --radius 0.3 --eye 0.5,0.5,0.5 --target 0.5,1,0.5 --fov 90 --size 16x16 -o "$dir/ao_l.pfm"
expect_ok "meshao --pattern random" "$dir/ao_x.pfm" meshao "$dir/cube.obj" --pattern random --two-sided --rays 64 --radius 0.3 --eye 0.5,0.5,0.5 --target 0.5,1,0.5 --fov 90 --size 16x16 -o "$dir/ao_x.pfm"
expect_ok "meshao inside, default pattern" "$dir/ao_d.pfm" meshao "$dir/cube.obj" --two-sided --rays 64 --radius 0.3 --eye 0.5,0.5,0.5 --target 0.5,1,0.5 --fov 90 --size 16x16 -o "$dir/ao_d.pfm"
cmp -s "$dir/ao_d.pfm" "$dir/ao_t.pfm" && ok "meshao: torus is the default pattern" || bad "meshao: --pattern torus differs from the default"
! cmp -s "$dir/ao_t.pfm" "$dir/ao_l.pfm" && ! cmp -s "$dir/ao_t.pfm" "$dir/ao_x.pfm" && ok "meshao: lloyd and random differ from torus" || bad "meshao: --pattern has no effect"
expect_ok "meshao inside the cube, two-sided, linear, lut, stats" "$dir/ao_i.pgm" meshao "$dir/cube.obj" --two-sided --falloff linear --lut 16 --rays 96 --radius 2 --eye 0.5,0.5,0.5 --target 0.5,1,0.5 --fov 90 --size 16x16 --seed 3 --no-jitter --stats -o "$dir/ao_i.pgm"
grep -q '^receivers: 256$' "$dir/stdout" && ok "meshao inside: 256 receivers" || bad "meshao stats: $(cat "$dir/stdout")"

# visfield: build a field of the cube, then AO images of the ground from the field and by ray casting.
expect_ok "visfield build" "$dir/cube.hfvf" visfield "$dir/cube.obj" --positions 82 --dirs 16 -o "$dir/cube.hfvf"
expect_ok "visfield --ao" "$dir/vfao.pgm" visfield --ao "$dir/cube.hfvf" --ground 0 --size 24x24 --rays 4 -o "$dir/vfao.pgm"
expect_ok "visfield --ao --reference" "$dir/vfar.pfm" visfield --ao "$dir/cube.hfvf" --ground 0 --size 24x24 --rays 4 --reference "$dir/cube.obj" -o "$dir/vfar.pfm"
# volgi: the room and a mesh with two lights render; every output choice and option parses.
expect_ok "volgi room" "$dir/vg.pfm" volgi --room --res 16 --iterations 16 --size 32x24 -o "$dir/vg.pfm"
grep -q '16 x 16 x 16 voxels' "$dir/stdout" && ok "volgi room grid" || bad "volgi room: $(cat "$dir/stdout")"
expect_ok "volgi room indirect, void paths, pgm" "$dir/vgi.pgm" volgi --room --res 16 --iterations 24 --paths void --transfer normalized --reflectance albedo --reflection diffuse --output indirect --size 32x24 -o "$dir/vgi.pgm"
expect_ok "volgi mesh, two lights, camera" "$dir/vgc.pfm" volgi "$dir/cube.obj" --res 8 --iterations 8 --albedo 0.5 --light point:2,-3,4:10 --light spot:0.5,0.5,3:0,0,-1:40,20:1,0.5,0.25 --eye 3,-4,2 --target 0.5,0.5,0.5 --fov 30 --size 16x16 --output direct -o "$dir/vgc.pfm"

expect_floats "viewshed: the hole is NaN" "$dir/vs7.pfm" 32 0 nan 1 1 1 1 1 1 1
expect_ok "visibility flat, 4 directions" "$dir/fv4.pfm" visibility "$f" --dirs 4 --stats -o "$dir/fv4.pfm"
expect_floats "visibility flat, 4 directions: 12" "$dir/fv4.pfm" 32 0 12 12 12 12 12 12 12 12
expect_floats "visibility flat, 4 directions: 12 (first row)" "$dir/fv4.pfm" 192 0 12 12 12 12 12 12 12 12
expect_stdout "visibility --stats: receiver-directions" "receiver-directions: 192"
expect_stdout "visibility --stats: visible" "visible per receiver-direction: 3"
expect_ok "visibility flat north" "$dir/fvn.pfm" visibility "$f" --dirs 1 --compass -o "$dir/fvn.pfm"
expect_floats "visibility flat north: y" "$dir/fvn.pfm" 192 0 5 5 5 5 5 5 5 5
expect_floats "visibility flat north: y (last row)" "$dir/fvn.pfm" 32 0 0 0 0 0 0 0 0 0
expect_ok "visibility flat --fraction" "$dir/fvf.pfm" visibility "$f" --dirs 1 --fraction --convention grid -o "$dir/fvf.pfm"
expect_floats "visibility flat --fraction: 1, 0 where nothing lies behind" "$dir/fvf.pfm" 32 0 1 1 1 1 1 1 1 0
expect_ok "visibility with a hole" "$dir/fv7.pfm" visibility "$dir/flat7.pgm" --nodata 7 --dirs 1 --convention grid -o "$dir/fv7.pfm"
expect_floats "visibility: the hole is NaN and never seen" "$dir/fv7.pfm" 32 0 nan 6 5 4 3 2 1 0

# ---- failures: one line, non-zero exit, nothing written -----------------------------------
o=$fdir/out.pfm
expect_fail "no arguments" 2
expect_fail "unknown command" 2 frobnicate "$h" -o "$o"
expect_fail "unknown option" 2 skyview "$h" --frob -o "$o"
expect_fail "missing IN" 2 skyview -o "$o"
expect_fail "two inputs" 2 skyview "$h" "$h" -o "$o"
expect_fail "missing -o" 2 skyview "$h"
expect_fail "-o without value" 2 skyview "$h" -o
expect_fail "-o unknown type" 2 skyview "$h" -o "$fdir/out.png"
expect_fail "missing file" 1 skyview "$dir/no-such-file.pgm" -o "$o"
expect_fail "garbage file" 1 skyview "$dir/garbage.pgm" -o "$o"
expect_fail "truncated PFM" 1 skyview "$dir/truncated.pfm" -o "$o"
expect_fail "colour image as heights" 1 skyview "$dir/env3.pfm" -o "$o"
expect_fail "unwritable output" 1 skyview "$h" -o "$fdir/no-such-dir/out.pfm"
for v in 0 -3 abc 1.5 '' ' 4' 4x 99999999999999999999 65537; do
  expect_fail "--dirs '$v'" 2 horizon "$h" --dirs "$v" -o "$o"
done
expect_fail "--dirs at the end" 2 horizon "$h" -o "$o" --dirs
for v in -1 0 nan inf -inf 1e999 '1 ' 2m; do
  expect_fail "--cell '$v'" 2 skyview "$h" --cell "$v" -o "$o"
done
expect_fail "--zscale 0" 2 skyview "$h" --zscale 0 -o "$o"
expect_fail "--zscale 1e300" 2 skyview "$h" --zscale 1e300 -o "$o"
expect_fail "--azimuth0 nan" 2 skyview "$h" --azimuth0 nan -o "$o"
expect_fail "--nodata nan" 2 skyview "$h" --nodata nan -o "$o"
expect_fail "--border foo" 2 skyview "$h" --border foo -o "$o"
expect_fail "--border-cells 0" 2 skyview "$h" --border clamp --border-cells 0 -o "$o"
expect_fail "--range 1:0" 2 skyview "$h" --range 1:0 -o "$fdir/out.pgm"
expect_fail "--range 5" 2 skyview "$h" --range 5 -o "$fdir/out.pgm"
expect_fail "--range with .pfm" 2 skyview "$h" --range 0:1 -o "$o"
expect_fail "--quiet=1" 2 skyview "$h" --quiet=1 -o "$o"
expect_fail "--sky on horizon" 2 horizon "$h" --sky 2 -o "$o"
expect_fail "--sky -1" 2 sky "$h" --sky -1 -o "$o"
expect_fail "--albedo x" 2 sky "$h" --albedo x -o "$o"
expect_fail "shadow without --sun-elevation" 2 shadow "$h" --sun-azimuth 90 -o "$o"
expect_fail "shadow without --sun-azimuth" 2 shadow "$h" --sun-elevation 30 -o "$o"
expect_fail "--sun-elevation 91" 2 shadow "$h" --sun-azimuth 90 --sun-elevation 91 -o "$o"
expect_fail "--sun-radius -1" 2 shadow "$h" --sun-azimuth 90 --sun-elevation 30 --sun-radius -1 -o "$o"
expect_fail "light without --env" 2 light "$h" -o "$o"
expect_fail "light --method foo" 2 light "$h" --env "$dir/env1.pfm" --method foo -o "$o"
expect_fail "light, missing env" 1 light "$h" --env "$dir/no-such-env.pfm" -o "$o"
expect_fail "light, garbage env" 1 light "$h" --env "$dir/garbage.pgm" -o "$o"
for v in -1 1.5 x 1001 ''; do
  expect_fail "indirect --bounces '$v'" 2 indirect "$h" --bounces "$v" -o "$o"
done
expect_fail "indirect --albedo-map of another size" 1 indirect "$h" --albedo-map "$f" -o "$o"
expect_fail "indirect --emission of another size" 1 indirect "$h" --emission "$dir/emit1.pfm" -o "$o"
expect_fail "indirect --sun-azimuth without --sun-elevation" 2 indirect "$h" --sun-azimuth 90 -o "$o"
expect_fail "indirect --sun-elevation without --sun-azimuth" 2 indirect "$h" --sun-elevation 20 -o "$o"
expect_fail "indirect --sun-radius without a sun" 2 indirect "$h" --sun-radius 1 -o "$o"
expect_fail "indirect --sun-irradiance without a sun" 2 indirect "$h" --sun-irradiance 2 -o "$o"
expect_fail "indirect --sun-irradiance -1" 2 indirect "$h" --sun-azimuth 90 --sun-elevation 20 --sun-irradiance -1 -o "$o"
expect_fail "indirect --sun-elevation 100" 2 indirect "$h" --sun-azimuth 90 --sun-elevation 100 -o "$o"
expect_fail "indirect --albedo with --albedo-map" 2 indirect "$f" --albedo 0.5 --albedo-map "$dir/alb51.pgm" -o "$o"
expect_fail "indirect --sky with --env" 2 indirect "$h" --sky 2 --env "$dir/env1.pfm" -o "$o"
expect_fail "indirect --albedo -0.5" 2 indirect "$h" --albedo -0.5 -o "$o"
expect_fail "indirect --output direct --bounces 2" 2 indirect "$h" --output direct --bounces 2 -o "$o"
expect_fail "indirect --output indirect --bounces 0" 2 indirect "$h" --output indirect --bounces 0 -o "$o"
expect_fail "indirect --output foo" 2 indirect "$h" --output foo -o "$o"
expect_fail "indirect --method" 2 indirect "$h" --method lp -o "$o"
expect_fail "indirect, missing albedo map" 1 indirect "$h" --albedo-map "$dir/no-such-map.pgm" -o "$o"
expect_fail "indirect, garbage emission" 1 indirect "$h" --emission "$dir/garbage.pgm" -o "$o"
expect_fail "indirect, negative map value" 1 indirect "$f" --emission "$dir/neg.pfm" -o "$o"
expect_fail "indirect, NaN map value off the holes" 1 indirect "$f" --albedo-map "$dir/nanrow.pfm" -o "$o"
expect_fail "indirect, garbage env" 1 indirect "$h" --env "$dir/garbage.pgm" -o "$o"
expect_fail "visibility --dirs 0" 2 visibility "$h" --dirs 0 -o "$o"
expect_fail "visibility --fraction=1" 2 visibility "$h" --fraction=1 -o "$o"
expect_fail "visibility --albedo" 2 visibility "$h" --albedo 1 -o "$o"
expect_fail "visibility --stats, garbage input" 1 visibility "$dir/garbage.pgm" --stats -o "$o"
[ ! -s "$dir/stdout" ] && ok "visibility --stats prints nothing on failure" || bad "visibility --stats printed on failure"
expect_fail "viewshed without --observer" 2 viewshed "$h" -o "$o"
expect_fail "viewshed --observer 3" 2 viewshed "$h" --observer 3 -o "$o"
expect_fail "viewshed --observer x,1" 2 viewshed "$h" --observer x,1 -o "$o"
expect_fail "viewshed observer outside the grid" 1 viewshed "$h" --observer 24,0 -o "$o"
expect_fail "viewshed --observer-height -1" 2 viewshed "$h" --observer 1,1 --observer-height -1 -o "$o"
expect_fail "viewshed --sky" 2 viewshed "$h" --observer 1,1 --sky 1 -o "$o"
expect_fail "shadow --observer" 2 shadow "$h" --observer 1,1 --sun-azimuth 1 --sun-elevation 1 -o "$o"
ob=$fdir/out.binvox
expect_fail "voxelize without --res" 2 voxelize "$dir/cube.obj" -o "$ob"
expect_fail "voxelize to .pfm" 2 voxelize "$dir/cube.obj" --res 4 -o "$o"
expect_fail "voxelize --mode bogus" 2 voxelize "$dir/cube.obj" --res 4 --mode bogus -o "$ob"
expect_fail "voxelize --res 0" 2 voxelize "$dir/cube.obj" --res 0 -o "$ob"
expect_fail "voxelize solid --axis all" 2 voxelize "$dir/cube.obj" --res 4 --mode solid --axis all -o "$ob"
expect_fail "voxelize --max-vertices with the pixel rule" 2 voxelize "$dir/cube.obj" --res 4 --max-vertices 7 -o "$ob"
expect_fail "meshao --method" 2 meshao "$dir/cube.obj" --method lsao -o "$o"
expect_fail "meshao --rays 0" 2 meshao "$dir/cube.obj" --rays 0 -o "$o"
expect_fail "meshao --pattern" 2 meshao "$dir/cube.obj" --pattern box -o "$o"
expect_fail "meshao --size" 2 meshao "$dir/cube.obj" --size 10 -o "$o"
expect_fail "meshao --eye" 2 meshao "$dir/cube.obj" --eye 1,2 -o "$o"
expect_fail "meshao --lut too big" 1 meshao "$dir/cube.obj" --rays 1024 --falloff linear --lut 128 -o "$o"
expect_fail "meshao empty mesh" 1 meshao "$dir/garbage.pgm" -o "$o"
expect_fail "visfield --positions 83" 2 visfield "$dir/cube.obj" --positions 83 -o "$fdir/x.hfvf"
expect_fail "visfield build with --ground" 2 visfield "$dir/cube.obj" --ground 0 -o "$fdir/x.hfvf"
expect_fail "visfield --ao of a mesh" 1 visfield --ao "$dir/cube.obj" -o "$o"
expect_fail "visfield --ao with --positions" 2 visfield --ao "$dir/cube.obj" --positions 82 -o "$o"
expect_fail "visfield missing mesh" 1 visfield "$dir/none.obj" -o "$fdir/x.hfvf"
expect_fail "volgi without MESH or --room" 2 volgi -o "$o"
expect_fail "volgi --room with MESH" 2 volgi "$dir/cube.obj" --room -o "$o"
expect_fail "volgi --light bogus" 2 volgi --room --light lamp:1,2,3 -o "$o"
expect_fail "volgi --light spot without angle" 2 volgi --room --light spot:0,0,1:0,0,-1 -o "$o"
expect_fail "volgi --light dir 0,0,0" 2 volgi --room --light dir:0,0,0 -o "$o"
expect_fail "volgi --res 1" 2 volgi --room --res 1 -o "$o"
expect_fail "volgi --albedo with --room" 2 volgi --room --albedo 0.5 -o "$o"
expect_fail "volgi --size 0x4" 2 volgi --room --size 0x4 -o "$o"
expect_fail "volgi --reflectance 2" 2 volgi --room --reflectance 2 -o "$o"
expect_fail "volgi eye = target" 2 volgi --room --eye 0.5,0.5,0.5 --target 0.5,0.5,0.5 -o "$o"
expect_fail "volgi missing mesh file" 1 volgi "$dir/nope.obj" -o "$o"
expect_fail "voxelize slicing --max-vertices 5" 2 voxelize "$dir/cube.obj" --res 4 --method slicing --max-vertices 5 -o "$ob"
expect_fail "voxelize --open surface" 2 voxelize "$dir/cube.obj" --res 4 --open -o "$ob"
expect_fail "voxelize an open mesh solid" 1 voxelize "$dir/tri.obj" --res 4 --mode solid -o "$ob"
expect_fail "voxelize garbage" 1 voxelize "$dir/garbage.pgm" --res 4 -o "$ob"
expect_fail "voxelize missing file" 1 voxelize "$dir/none.obj" --res 4 -o "$ob"
expect_fail "ssao --method nope" 2 ssao "$dir/plane.pfm" --method nope -o "$o"
expect_fail "ssao --depth gl without planes" 2 ssao "$dir/plane.pfm" --depth gl -o "$o"
expect_fail "ssao guard too big" 2 ssao "$dir/plane.pfm" --guard 10 -o "$o"
expect_fail "ssao --fov-y 0" 2 ssao "$dir/plane.pfm" --fov-y 0 -o "$o"
expect_fail "ssao garbage" 1 ssao "$dir/garbage.pgm" -o "$o"
expect_fail "gi --shininess without --specular" 2 gi "$h" --shininess 8 -o "$o"
expect_fail "gi --order 5" 2 gi "$h" --order 5 -o "$o"
expect_fail "gi --sun-azimuth alone" 2 gi "$h" --sun-azimuth 90 -o "$o"
expect_fail "gi garbage" 1 gi "$dir/garbage.pgm" -o "$o"
expect_fail "horizon over the size limit" 1 horizon "$dir/big.pgm" --dirs 65536 -o "$o"
grep -q 'HFVIS_ERR_LIMIT' "$dir/stderr" && ok "horizon limit names HFVIS_ERR_LIMIT" || bad "horizon limit names HFVIS_ERR_LIMIT"

# A failed run leaves an existing OUT untouched.
printf 'old\n' > "$dir/keep.pfm"
"$hfvis" skyview "$dir/garbage.pgm" -o "$dir/keep.pfm" 2> /dev/null
[ "$(cat "$dir/keep.pfm")" = old ] && ok "failed run keeps the old OUT" || bad "failed run keeps the old OUT"

# ---- split runs: --dir-range A:B writes a partial result, `hfvis sum` adds the parts ----------
# Each supported command split 4 ways (parts summed in shuffled order) must give the single run's
# file. The parts carry double sums, so the output is bit-exact unless a value lies within about
# K*2^-53 of a float rounding boundary; then it may differ by one ulp, which same_or_ulp accepts
# for PFM (adjacent floats of one sign differ by 1 as unsigned integers).
same_or_ulp() {
  name=$1; a=$2; b=$3
  if cmp -s "$a" "$b"; then ok "$name: bit-exact"; return; fi
  if [ "$little_endian" = 1 ] && [ "$(wc -c < "$a")" = "$(wc -c < "$b")" ] && \
     [ "$(head -n 3 "$a")" = "$(head -n 3 "$b")" ]; then
    hb=$(head -n 3 "$a" | wc -c | tr -d ' ')
    tail -c +$((hb + 1)) "$a" | od -An -v -tu4 | tr -s ' ' '\n' | grep . > "$dir/ulp_a"
    tail -c +$((hb + 1)) "$b" | od -An -v -tu4 | tr -s ' ' '\n' | grep . > "$dir/ulp_b"
    if paste "$dir/ulp_a" "$dir/ulp_b" | awk '{ d = $1 - $2; if (d > 1 || d < -1) bad = 1 } END { exit bad }'; then
      ok "$name: within one ulp"; return; fi
  fi
  bad "$name: $b differs from $a"
}
# split4 NAME CMD EXT RANGES... -- ARGS...: the single run, one part per range, sum (parts in
# reverse order), compare.
split4() {
  name=$1; cmd=$2; ext=$3; shift 3; ranges=""
  while [ "$1" != "--" ]; do ranges="$ranges $1"; shift; done; shift
  rm -f "$dir"/part_*.hfvs
  in=${split_in:-$h} # the input: hill.pgm unless split_in names another
  "$hfvis" "$cmd" "$in" "$@" -o "$dir/single.$ext" 2> "$dir/stderr" || { bad "$name: single run: $(cat "$dir/stderr")"; return; }
  parts=""
  for r in $ranges; do
    p=$dir/part_${r%%:*}.hfvs
    "$hfvis" "$cmd" "$in" "$@" --dir-range "$r" -o "$p" 2> "$dir/stderr" || { bad "$name: part $r: $(cat "$dir/stderr")"; return; }
    parts="$p $parts"
  done
  # shellcheck disable=SC2086
  "$hfvis" sum $parts -o "$dir/summed.$ext" 2> "$dir/stderr" || { bad "$name: sum: $(cat "$dir/stderr")"; return; }
  if [ "$ext" = pfm ]; then same_or_ulp "$name" "$dir/single.$ext" "$dir/summed.$ext"
  elif cmp -s "$dir/single.$ext" "$dir/summed.$ext"; then ok "$name: bit-exact"
  else bad "$name: $dir/summed.$ext differs from the single run"; fi
}
split4 "split horizon 4 ways" horizon pfm 0:3 3:8 8:13 13:16 -- --dirs 16 --degrees
split4 "split horizon K=6 (no quarter turns)" horizon pfm 0:1 1:3 3:4 4:6 -- --dirs 6 --border wrap
split4 "split skyview 4 ways" skyview pfm 0:3 3:8 8:13 13:16 -- --dirs 16 --border clamp
split4 "split skyview 4 ways, PGM" skyview pgm 0:4 4:8 8:12 12:16 -- --dirs 16 --compass
split4 "split sky 4 ways" sky pfm 0:5 5:6 6:11 11:12 -- --dirs 12 --sky 2 --albedo 0.5 --azimuth0 0.25
split4 "split light 4 ways (RGB)" light pfm 0:3 3:8 8:13 13:16 -- --dirs 16 --env "$dir/env3.pfm" --albedo 0.8
split4 "split light --method lp" light pfm 0:1 1:2 2:3 3:8 -- --dirs 8 --env "$dir/env1.pfm" --method lp
split4 "split visibility 4 ways" visibility pfm 0:2 2:4 4:6 6:8 -- --dirs 8
# a raster OUT: the sum writes the single run's GeoTIFF byte for byte, with the horizon's band
# labels (rebuilt from the parts' tags) and visibility's integer counts
split4 "split horizon --exact --convention grid, GeoTIFF with its band labels" horizon tif 0:4 4:8 -- --dirs 8 --exact --convention grid --degrees
if command -v gdalinfo > /dev/null 2>&1; then
  gdalinfo "$dir/single.tif" | grep 'Description = ' > "$dir/desc_single"
  gdalinfo "$dir/summed.tif" | grep 'Description = ' > "$dir/desc_summed"
  [ "$(wc -l < "$dir/desc_summed")" -eq 8 ] && cmp -s "$dir/desc_single" "$dir/desc_summed" &&
    ok "sum: the GeoTIFF's 8 band descriptions are the single run's (gdalinfo)" ||
    bad "sum: band descriptions: $(head -n 2 "$dir/desc_summed")"
else
  echo "SKIP cli sum band descriptions: no gdalinfo (the byte comparison above covers them)"
fi
split4 "split visibility, GeoTIFF" visibility tif 0:4 4:8 -- --dirs 8
# georeferenced parts carry the input's georeference (the tag's geo=): their sum writes the
# single run's GeoTIFF, ASC + .prj and EHdr + .hdr + .prj byte for byte. geo.tif: a GeoTIFF with
# GeoKeys, an ESRI PE string (from the .prj), NoData and a hole, made from geo.asc + geo.prj
awk 'BEGIN { print "ncols 9"; print "nrows 7"; print "xllcorner 500000"; print "yllcorner 5000000"
  print "cellsize 10"; print "NODATA_value -9999"; for (y = 0; y < 7; y++) { s = ""
  for (x = 0; x < 9; x++) s = s " " (x == 4 && y == 3 ? -9999 : 100 + x * y + (7 * x + 3 * y) % 5); print s } }' > "$dir/geo.asc"
printf '%s' 'PROJCS["WGS_1984_UTM_Zone_33N",GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984",SPHEROID["WGS_1984",6378137.0,298.257223563]],PRIMEM["Greenwich",0.0],UNIT["Degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],PARAMETER["False_Easting",500000.0],PARAMETER["False_Northing",0.0],PARAMETER["Central_Meridian",15.0],PARAMETER["Scale_Factor",0.9996],PARAMETER["Latitude_Of_Origin",0.0],UNIT["Meter",1.0]]' > "$dir/geo.prj"
"$hfvis" hillshade "$dir/geo.asc" --quiet -o "$dir/geo.tif" 2> "$dir/stderr" || bad "sum: making geo.tif: $(cat "$dir/stderr")"
split_in=$dir/geo.tif
split4 "split horizon of a GeoTIFF, GeoTIFF" horizon tif 0:2 2:5 5:8 -- --dirs 8 --degrees
split4 "split skyview of a GeoTIFF, GeoTIFF" skyview tif 0:4 4:8 -- --dirs 8 --border clamp
split4 "split skyview of a GeoTIFF, ASC" skyview asc 0:3 3:8 -- --dirs 8
cmp -s "$dir/single.prj" "$dir/summed.prj" && ok "sum: the ASC's .prj is the single run's" ||
  bad "sum: the ASC's .prj differs from the single run's"
split4 "split horizon of a GeoTIFF, EHdr" horizon bil 0:4 4:8 -- --dirs 8
cmp -s "$dir/single.hdr" "$dir/summed.hdr" && cmp -s "$dir/single.prj" "$dir/summed.prj" &&
  ok "sum: the EHdr's .hdr and .prj are the single run's" || bad "sum: the EHdr's .hdr or .prj differs"
split_in=$dir/geo.asc
split4 "split skyview of an ASC + .prj, ASC" skyview asc 0:4 4:8 -- --dirs 8
cmp -s "$dir/single.prj" "$dir/summed.prj" && ok "sum: the ASC input's .prj reaches the sum's" ||
  bad "sum: the ASC input's .prj: the sum's differs from the single run's"
split_in=
# parts whose inputs have the same heights but another georeference are refused, naming what differs
sed 's/xllcorner 500000/xllcorner 500010/' "$dir/geo.asc" > "$dir/geo_moved.asc"; cp "$dir/geo.prj" "$dir/geo_moved.prj"
cp "$dir/geo.asc" "$dir/geo_noprj.asc"
"$hfvis" skyview "$dir/geo.asc" --dirs 8 --dir-range 0:4 -o "$dir/geo_a.hfvs" 2> /dev/null
"$hfvis" skyview "$dir/geo_moved.asc" --dirs 8 --dir-range 4:8 -o "$dir/geo_b.hfvs" 2> /dev/null
"$hfvis" skyview "$dir/geo_noprj.asc" --dirs 8 --dir-range 4:8 -o "$dir/geo_c.hfvs" 2> /dev/null
expect_fail "sum refuses parts of another origin" 1 sum "$dir/geo_a.hfvs" "$dir/geo_b.hfvs" -o "$fdir/x.tif"
grep -q 'georeference (geotransform' "$dir/stderr" && ok "sum: another origin named" || bad "sum: another origin: $(cat "$dir/stderr")"
expect_fail "sum refuses parts of another CRS, even to .pfm" 1 sum "$dir/geo_a.hfvs" "$dir/geo_c.hfvs" -o "$fdir/x.pfm"
grep -q "georeference (CRS: the .prj's WKT)" "$dir/stderr" && ok "sum: another CRS named" || bad "sum: another CRS: $(cat "$dir/stderr")"
# a georeference too long for the tag (a 3.5 kB .prj): the parts still sum to .pfm, a raster OUT
# is refused in one line, and their fingerprint keeps them apart from other georeferences' parts
cp "$dir/geo.asc" "$dir/geo_long.asc"
longname=$(awk 'BEGIN { for (i = 0; i < 3200; i++) printf "%c", 97 + i % 26 }')
sed "s/WGS_1984_UTM_Zone_33N/$longname/" "$dir/geo.prj" > "$dir/geo_long.prj"
"$hfvis" skyview "$dir/geo_long.asc" --dirs 8 --dir-range 0:4 -o "$dir/geo_l1.hfvs" 2> /dev/null
"$hfvis" skyview "$dir/geo_long.asc" --dirs 8 --dir-range 4:8 -o "$dir/geo_l2.hfvs" 2> /dev/null
"$hfvis" skyview "$dir/geo_long.asc" --dirs 8 -o "$dir/geo_long_single.pfm" 2> /dev/null
"$hfvis" sum "$dir/geo_l1.hfvs" "$dir/geo_l2.hfvs" -o "$dir/geo_long_sum.pfm" 2> "$dir/stderr" &&
  cmp -s "$dir/geo_long_single.pfm" "$dir/geo_long_sum.pfm" && ok "sum: parts of a long georeference to .pfm" ||
  bad "sum: parts of a long georeference to .pfm: $(cat "$dir/stderr")"
expect_fail "sum refuses a raster OUT of a georeference too long for the tag" 1 sum "$dir/geo_l1.hfvs" "$dir/geo_l2.hfvs" -o "$fdir/x.tif"
grep -q 'too long for a part' "$dir/stderr" && ok "sum: the long georeference named" || bad "sum: long georeference: $(cat "$dir/stderr")"
expect_fail "sum refuses a long georeference's part beside another's" 1 sum "$dir/geo_l1.hfvs" "$dir/geo_b.hfvs" -o "$fdir/x.pfm"
# retag PART SED OUT: PART with its tag rewritten by SED and its CRC-32 recomputed (gzip's trailer
# holds the CRC-32 of what it compressed, least significant byte first, as a part does)
retag() {
  total=$(wc -c < "$1"); head3=$(head -n 3 "$1" | wc -c)
  { head -n 2 "$1"; sed -n 3p "$1" | sed "$2"; head -c $((total - 4)) "$1" | tail -c +$((head3 + 1)); } > "$3.body"
  { cat "$3.body"; gzip -c < "$3.body" | tail -c 8 | head -c 4; } > "$3"
  rm -f "$3.body"
}
if command -v gzip > /dev/null 2>&1; then
  # a part of an older hfvis (tag "georef=1", no geo=) is refused, never summed without its
  # georeference, even to .pfm
  retag "$dir/geo_a.hfvs" 's/ geo=[^ ]*$/ georef=1/' "$dir/old.hfvs"
  "$hfvis" sum "$dir/old.hfvs" -o "$dir/old.pfm" 2> "$dir/stderr"
  grep -q 'older hfvis.*rerun its --dir-range' "$dir/stderr" && ok "sum refuses a part of an older hfvis (no geo=)" ||
    bad "sum: older part: $(cat "$dir/stderr")"
  rm -f "$dir/old.pfm"
  # a georeference cut short, with a byte past its end, or outside base64url: "damaged part"
  "$hfvis" skyview "$dir/geo.asc" --dirs 8 --dir-range 0:8 -o "$dir/geo_all.hfvs" 2> /dev/null
  geo=$(sed -n 3p "$dir/geo_all.hfvs" | sed 's/.* geo=//'); cut_bad=0
  for g in "$(echo "$geo" | cut -c 1-40)" "$(echo "$geo" | cut -c 1-$((${#geo} - 4)))" "${geo}AA" "AAAA" "A" "${geo%?}*"; do
    retag "$dir/geo_all.hfvs" "s/ geo=[^ ]*\$/ geo=$g/" "$dir/cut.hfvs"
    "$hfvis" sum "$dir/cut.hfvs" -o "$dir/cut.tif" > /dev/null 2> "$dir/stderr"; rc=$?
    if [ "$rc" -ne 1 ] || ! grep -q 'damaged part: its georeference' "$dir/stderr" || [ -e "$dir/cut.tif" ]; then
      bad "sum of a part with geo=${g%"${g#?????}"}... (${#g} chars): exit $rc: $(cat "$dir/stderr")"; cut_bad=1; break
    fi
  done
  [ "$cut_bad" -eq 0 ] && ok "sum: damaged georeferences (cut, extended, foreign characters) refused"
  rm -f "$dir/cut.hfvs"
else
  echo "SKIP cli sum of an older or damaged part: no gzip"
fi
split4 "split visibility --fraction" visibility pfm 0:3 3:4 4:7 7:8 -- --dirs 8 --fraction --zscale 3
# exact rays (--exact): split runs and sums as for the lattice; mixing modes is refused
split4 "split horizon --exact" horizon pfm 0:3 3:8 8:13 13:16 -- --dirs 16 --exact
split4 "split skyview --exact" skyview pfm 0:4 4:8 8:12 12:16 -- --dirs 16 --exact --border clamp
split4 "split sky --exact" sky pfm 0:5 5:6 6:11 11:12 -- --dirs 12 --exact --sky 2 --albedo 0.5 --azimuth0 0.25
split4 "split light --exact" light pfm 0:3 3:8 8:13 13:16 -- --dirs 16 --exact --env "$dir/env3.pfm"
"$hfvis" skyview "$h" --dirs 8 --exact --dir-range 0:4 -o "$dir/mx_e.hfvs" 2> /dev/null
"$hfvis" skyview "$h" --dirs 8 --dir-range 4:8 -o "$dir/mx_l.hfvs" 2> /dev/null
expect_fail "sum refuses exact and lattice parts" 1 sum "$dir/mx_e.hfvs" "$dir/mx_l.hfvs" -o "$fdir/x.pfm"
"$hfvis" skyview "$dir/flat.pgm" --exact --dirs 7 -o "$dir/svf_flat.pfm" && [ "$(last_bytes "$dir/svf_flat.pfm" 4)" = "00 00 80 3f" ] \
  && ok "skyview --exact on flat: 1" || bad "skyview --exact on flat: 1"
"$hfvis" sky "$dir/flat.pgm" --exact --dirs 5 --sky 2 --albedo 0.5 -o "$dir/sky_flat.pfm" && \
  [ "$(last_bytes "$dir/sky_flat.pfm" 4)" = "00 00 80 3f" ] && ok "sky --exact on flat: albedo*c" || bad "sky --exact on flat: albedo*c"
"$hfvis" shadow "$h" --sun-azimuth 130 --sun-elevation 25 --exact -o "$dir/sh_e.pfm" && ok "shadow --exact" || bad "shadow --exact"
# --exact-near D (hfvis_sweep_options.ray_near_cells): reaches the library (K = 64 on a 48 x 40
# hill: most lines are longer than 8 cells between grid points, so D = 8 takes the far field and
# differs from the sweep; D = 0 and D beyond every line are the sweep byte for byte), is the same
# on 1 and 2 threads and in parts, and is refused without exact rays, with a radius, out of range
awk 'BEGIN { w = 48; h = 40; print "P2"; print w, h; print 255
  for (y = 0; y < h; y++) { s = ""; for (x = 0; x < w; x++) s = s " " int(128 + 100 * sin(x / 3) * cos(y / 4) + 20 * sin(x * y / 7)); print s } }' > "$dir/hill48.pgm"
h48=$dir/hill48.pgm
expect_ok "horizon --exact --exact-near 8" "$dir/en8.pfm" horizon "$h48" --dirs 64 --exact --exact-near 8 -o "$dir/en8.pfm"
"$hfvis" horizon "$h48" --dirs 64 --exact --quiet -o "$dir/en_sweep.pfm" &&
  "$hfvis" horizon "$h48" --dirs 64 --exact --exact-near 0 --quiet -o "$dir/en0.pfm" &&
  "$hfvis" horizon "$h48" --dirs 64 --exact --exact-near 400 --quiet -o "$dir/en400.pfm" &&
  cmp -s "$dir/en_sweep.pfm" "$dir/en0.pfm" && cmp -s "$dir/en_sweep.pfm" "$dir/en400.pfm" &&
  ok "--exact-near 0 and 400 (beyond every line): the sweep byte for byte" || bad "--exact-near 0/400 differ from --exact"
cmp -s "$dir/en_sweep.pfm" "$dir/en8.pfm" && bad "--exact-near 8: the same bytes as the sweep (not passed on?)" ||
  ok "--exact-near 8: the near and far field (differs from the sweep)"
"$hfvis" skyview "$h48" --dirs 64 --exact --exact-near 8 --threads 1 --quiet -o "$dir/ent1.pfm" &&
  "$hfvis" skyview "$h48" --dirs 64 --exact --exact-near 8 --threads 2 --quiet -o "$dir/ent2.pfm" &&
  cmp -s "$dir/ent1.pfm" "$dir/ent2.pfm" && ok "skyview --exact-near 8: --threads 2 = --threads 1" || bad "skyview --exact-near 8: threads differ"
"$hfvis" skyview "$dir/flat.pgm" --exact --exact-near 2 --dirs 64 -o "$dir/svf_flat_en.pfm" && [ "$(last_bytes "$dir/svf_flat_en.pfm" 4)" = "00 00 80 3f" ] \
  && ok "skyview --exact-near 2 on flat: 1" || bad "skyview --exact-near 2 on flat: 1"
split4 "split skyview --exact --exact-near 8" skyview pfm 0:16 16:32 32:48 48:64 -- --dirs 64 --exact --exact-near 8
"$hfvis" skyview "$h" --dirs 8 --exact --exact-near 2 --dir-range 0:4 -o "$dir/en_p.hfvs" 2> /dev/null
"$hfvis" skyview "$h" --dirs 8 --exact --dir-range 4:8 -o "$dir/en_q.hfvs" 2> /dev/null
expect_fail "sum refuses parts of different --exact-near" 1 sum "$dir/en_p.hfvs" "$dir/en_q.hfvs" -o "$fdir/x.pfm"
expect_fail "--exact-near without --exact" 2 skyview "$h" --dirs 64 --exact-near 8 -o "$fdir/x.pfm"
expect_fail "--exact-near with --max-distance" 2 horizon "$h" --dirs 64 --exact --exact-near 8 --max-distance 10 -o "$fdir/x.pfm"
expect_fail "--exact-near 65537" 2 skyview "$h" --dirs 64 --exact --exact-near 65537 -o "$fdir/x.pfm"
expect_fail "--exact-near -1" 2 skyview "$h" --dirs 64 --exact --exact-near -1 -o "$fdir/x.pfm"
expect_fail "hillshade --lattice --exact-near" 2 hillshade "$h" --lattice --exact-near 8 -o "$fdir/x.pfm"
expect_ok "hillshade --exact-near (exact by default)" "$dir/hs_en.pfm" hillshade "$h48" --exact-near 8 -o "$dir/hs_en.pfm"
expect_fail "viewshed --exact-near" 2 viewshed "$h" --observer 1,1 --exact --exact-near 8 -o "$fdir/x.pfm"
expect_fail "visibility --exact" 2 visibility "$h" --exact -o "$fdir/x.pfm"
expect_fail "indirect --exact" 2 indirect "$h" --exact -o "$fdir/x.pfm"
expect_fail "gi --exact" 2 gi "$h" --exact -o "$fdir/x.pfm"
# hfvis azimuths: K lines in output-plane order, both modes
[ "$("$hfvis" azimuths --dirs 4 | tr '\n' ' ')" = "0 90 180 270 " ] && ok "azimuths lattice" || bad "azimuths lattice"
[ "$("$hfvis" azimuths --dirs 4 --compass --azimuth0 0 | tr '\n' ' ')" = "0 90 180 270 " ] && ok "azimuths --compass" || bad "azimuths --compass"
awk -v v="$("$hfvis" azimuths --dirs 16 --exact | sed -n 2p)" 'BEGIN { exit !(v - 21.801409486351812 < 1e-12 && 21.801409486351812 - v < 1e-12) }' && ok "azimuths --exact: atan(2/5)" || bad "azimuths --exact: atan(2/5)"
[ "$("$hfvis" azimuths --dirs 4 --convention grass --azimuth0 0 | tr '\n' ' ')" = "0 90 180 270 " ] && ok "azimuths --convention grass" || bad "azimuths --convention grass"
[ "$("$hfvis" azimuths --dirs 4 --convention grid --azimuth0 0.5 --radians | sed -n 1p)" = "28.647889756541161" ] && ok "azimuths --radians" || bad "azimuths --radians"
[ "$("$hfvis" azimuths --dirs 64 --exact | wc -l | tr -d ' ')" = 64 ] && ok "azimuths --exact: 64 lines" || bad "azimuths --exact: 64 lines"
expect_fail "azimuths without --dirs" 2 azimuths --exact
expect_fail "azimuths --dirs 0" 2 azimuths --dirs 0
expect_fail "azimuths unknown option" 2 azimuths --dirs 4 -o "$fdir/x.txt"
expect_fail "azimuths --azimuth0 nan" 2 azimuths --dirs 4 --azimuth0 nan
# azimuths shares the run commands' parsing: IN is taken, --azimuth0 1e20 is refused as skyview refuses it
[ "$("$hfvis" azimuths "$h" --dirs 4 --azimuth0 10 | tr '\n' ' ')" = "10 100 190 280 " ] && ok "azimuths IN --dirs 4" || bad "azimuths IN --dirs 4"
expect_fail "azimuths --azimuth0 1e20" 2 azimuths --dirs 4 --azimuth0 1e20
grep -q -- '--azimuth0' "$dir/stderr" && ok "azimuths --azimuth0 1e20: names the flag" || bad "azimuths --azimuth0 1e20: $(cat "$dir/stderr")"
expect_fail "azimuths of a file that is not a raster" 1 azimuths "$dir/garbage.pgm" --dirs 4
# a flag a command does not use is refused by name; a bad value names its flag and range
expect_fail "skyview --sun-elevation" 2 skyview "$h" --sun-elevation 20 -o "$fdir/x.pfm"
grep -qF 'hfvis: skyview: --sun-elevation is not used by skyview' "$dir/stderr" && ok "skyview --sun-elevation: named" || bad "skyview --sun-elevation: $(cat "$dir/stderr")"
expect_fail "viewshed --dirs" 2 viewshed "$h" --observer-grid 3,3 --dirs 8 -o "$fdir/x.pfm"
expect_fail "viewshed --border clamp" 2 viewshed "$h" --observer-grid 3,3 --border clamp -o "$fdir/x.pfm"
# one observer: --observer and --observer-grid together (or twice) are refused, not the later one taken
expect_fail "viewshed --observer with --observer-grid" 2 viewshed "$h" --cell 2 --observer 1,1 --observer-grid 3,3 -o "$fdir/x.pfm"
expect_fail "viewshed --observer-grid twice" 2 viewshed "$h" --observer-grid 3,3 --observer-grid 2,2 -o "$fdir/x.pfm"
# hillshade --no-shadows: the flags that shape the cast shadows are refused, not ignored
for nsf in "--sun-radius 5" "--lattice" "--exact-near 8" "--max-distance 10"; do
  expect_fail "hillshade --no-shadows $nsf" 2 hillshade "$h" --no-shadows $nsf -o "$fdir/x.pfm"
done
expect_ok "hillshade --no-shadows --max-distance with --window (its halo)" "$dir/hnsw.pfm" hillshade "$dir/emit1.pfm" --no-shadows --max-distance 10 --window 0,0,4,4 -o "$dir/hnsw.pfm"
"$hfvis" visibility --help 2>&1 | grep -q "not a whole number" && ok "visibility --help: counts are not whole off the axes" || bad "visibility --help: no word on fractional counts"
expect_fail "normals --convention" 2 normals "$h" --convention grass -o "$fdir/x.pfm"
expect_fail "voxelize --range" 2 voxelize "$dir/hill.pgm" --res 4 --range 0:1 -o "$fdir/x.raw"
expect_fail "ssao --method lsao --dirs 4" 2 ssao "$dir/hill.pgm" --method lsao --dirs 4 -o "$fdir/x.pfm"
grep -q -- '--dirs.*multiple of 8' "$dir/stderr" && ok "ssao lsao --dirs 4: names --dirs and its range" || bad "ssao lsao --dirs 4: $(cat "$dir/stderr")"
"$hfvis" info "$dir/envhuge.pfm" | grep -qx 'format pfm' && ok "info: a PFM is pfm" || bad "info: PFM format"
"$hfvis" skyview "$h" --dirs 16 --dir-range 0:16 -o "$dir/whole.hfvs" 2> /dev/null
"$hfvis" sum "$dir/whole.hfvs" -o "$dir/whole.pfm" 2> /dev/null
"$hfvis" skyview "$h" --dirs 16 -o "$dir/single.pfm" 2> /dev/null
same_or_ulp "one part 0:K" "$dir/single.pfm" "$dir/whole.pfm"
head -n 1 "$dir/whole.hfvs" | grep -q '^HFVISSUM 2$' && ok "partial file magic" || bad "partial file magic"

# Refusals: one line, non-zero exit, nothing written.
for r in 0:4 4:8 8:12 12:16; do "$hfvis" skyview "$h" --dirs 16 --dir-range "$r" -o "$dir/sv_${r%%:*}.hfvs"; done
"$hfvis" skyview "$h" --dirs 16 --dir-range 2:6 -o "$dir/sv_2.hfvs"
"$hfvis" skyview "$h" --dirs 16 --dir-range 12:16 --cell 2 -o "$dir/sv_cell2.hfvs"
"$hfvis" skyview "$h" --dirs 16 --dir-range 12:16 --zscale 2 -o "$dir/sv_z2.hfvs"
"$hfvis" sky "$h" --dirs 16 --dir-range 12:16 -o "$dir/sky_12.hfvs"
"$hfvis" skyview "$h" --dirs 32 --dir-range 16:32 -o "$dir/sv32_16.hfvs"
"$hfvis" skyview "$dir/flat.pgm" --dirs 16 --dir-range 12:16 -o "$dir/flat_12.hfvs"
s0=$dir/sv_0.hfvs; s4=$dir/sv_4.hfvs; s8=$dir/sv_8.hfvs; s12=$dir/sv_12.hfvs
expect_fail "sum: overlapping ranges" 1 sum "$s0" "$s4" "$dir/sv_2.hfvs" "$s8" "$s12" -o "$o"
grep -q 'overlap' "$dir/stderr" && ok "sum: overlap is named" || bad "sum: overlap is named"
expect_fail "sum: the same part twice" 1 sum "$s0" "$s4" "$s4" "$s8" "$s12" -o "$o"
expect_fail "sum: a gap" 1 sum "$s0" "$s8" "$s12" -o "$o"
grep -q 'directions 4:8 of K = 16 are missing' "$dir/stderr" && ok "sum: gap is named" || bad "sum: gap is named"
expect_fail "sum: the last range missing" 1 sum "$s0" "$s4" "$s8" -o "$o"
grep -q 'directions 12:16 of K = 16 are missing' "$dir/stderr" && ok "sum: missing end is named" || bad "sum: missing end is named"
expect_fail "sum: different --cell" 1 sum "$s0" "$s4" "$s8" "$dir/sv_cell2.hfvs" -o "$o"
grep -q 'cell=' "$dir/stderr" && ok "sum: the differing parameter is named" || bad "sum: the differing parameter is named"
expect_fail "sum: different input (zscale)" 1 sum "$s0" "$s4" "$s8" "$dir/sv_z2.hfvs" -o "$o"
expect_fail "sum: different command" 1 sum "$s0" "$s4" "$s8" "$dir/sky_12.hfvs" -o "$o"
expect_fail "sum: different K" 1 sum "$s0" "$s4" "$s8" "$dir/sv32_16.hfvs" -o "$o"
expect_fail "sum: different grid" 1 sum "$s0" "$s4" "$s8" "$dir/flat_12.hfvs" -o "$o"
expect_fail "sum: garbage file" 1 sum "$s0" "$dir/garbage.pgm" -o "$o"
head -c 60 "$s0" > "$dir/trunc.hfvs"
expect_fail "sum: truncated part" 1 sum "$dir/trunc.hfvs" "$s4" "$s8" "$s12" -o "$o"
expect_fail "sum: missing part file" 1 sum "$dir/none.hfvs" -o "$o"
expect_fail "sum: no parts" 2 sum -o "$o"
expect_fail "sum: no -o" 2 sum "$s0"
expect_fail "sum: -o .hfvs" 2 sum "$s0" -o "$fdir/x.hfvs"
expect_fail "sum: --range with .pfm" 2 sum "$s0" --range 0:1 -o "$o"
expect_fail "sum: unknown option" 2 sum "$s0" --dirs 4 -o "$o"
expect_fail "--dir-range beyond K" 2 skyview "$h" --dirs 16 --dir-range 0:17 -o "$fdir/x.hfvs"
expect_fail "--dir-range empty" 2 skyview "$h" --dirs 16 --dir-range 3:3 -o "$fdir/x.hfvs"
expect_fail "--dir-range A>B" 2 skyview "$h" --dirs 16 --dir-range 5:2 -o "$fdir/x.hfvs"
expect_fail "--dir-range x:y" 2 skyview "$h" --dir-range x:y -o "$fdir/x.hfvs"
expect_fail "--dir-range -1:2" 2 skyview "$h" --dir-range -1:2 -o "$fdir/x.hfvs"
expect_fail "--dir-range to .pfm" 2 skyview "$h" --dir-range 0:4 -o "$o"
expect_fail ".hfvs without --dir-range" 2 skyview "$h" -o "$fdir/x.hfvs"
expect_fail "--dir-range with --range" 2 skyview "$h" --dir-range 0:4 --range 0:1 -o "$fdir/x.hfvs"
expect_fail "--dir-range on shadow" 2 shadow "$h" --sun-azimuth 1 --sun-elevation 1 --dir-range 0:4 -o "$fdir/x.hfvs"
expect_fail "--dir-range on gi" 2 gi "$h" --dir-range 0:4 -o "$fdir/x.hfvs"
expect_fail "--dir-range with --stats" 2 visibility "$h" --stats --dir-range 0:4 -o "$fdir/x.hfvs"
expect_fail "horizon part of an oversized map" 1 horizon "$dir/big.pgm" --dirs 65536 --dir-range 0:1 -o "$fdir/x.hfvs"
# Damaged parts (issue: a NaN or 1e308 planted in a body was summed, exit 0): one byte changed is
# caught by the CRC-32, a version-1 part (no checksum) is named as such, and a value outside its
# domain under a correct checksum (written here with crc32_le, POSIX sh arithmetic) is refused.
crc32_le() { # FILE: the CRC-32 (ISO-HDLC) of FILE as four printf octal escapes, little-endian
  od -An -v -tu1 "$1" | awk '{ for (i = 1; i <= NF; i++) print $i }' > "$dir/crc_bytes"
  c=4294967295
  while read -r b; do
    c=$(( c ^ b )); k=0
    while [ $k -lt 8 ]; do
      if [ $(( c & 1 )) -eq 1 ]; then c=$(( (c >> 1) ^ 3988292384 )); else c=$(( c >> 1 )); fi
      k=$((k + 1))
    done
  done < "$dir/crc_bytes"
  c=$(( c ^ 4294967295 ))
  printf '\\%03o\\%03o\\%03o\\%03o' $((c & 255)) $(((c >> 8) & 255)) $(((c >> 16) & 255)) $(((c >> 24) & 255))
}
"$hfvis" skyview "$dir/flat.pgm" --dirs 4 --dir-range 0:4 -o "$dir/f04.hfvs"
fsize=$(wc -c < "$dir/f04.hfvs" | tr -d ' ')
cp "$dir/f04.hfvs" "$dir/flip.hfvs"
printf '\377' | dd of="$dir/flip.hfvs" bs=1 seek=$((fsize - 12)) conv=notrunc 2>/dev/null
expect_fail "sum: a body byte changed" 1 sum "$dir/flip.hfvs" -o "$o"
grep -q 'CRC-32' "$dir/stderr" && ok "sum: damaged part named" || bad "sum: damaged part named: $(cat "$dir/stderr")"
{ printf 'HFVISSUM 1\n'; tail -c +12 "$dir/f04.hfvs" | head -c $((fsize - 15)); } > "$dir/v1.hfvs"
expect_fail "sum: a version-1 part" 1 sum "$dir/v1.hfvs" -o "$o"
grep -q 'version-1 part' "$dir/stderr" && ok "sum: version-1 part named" || bad "sum: version-1 part named: $(cat "$dir/stderr")"
# 1e308 (0x7fe1ccf385ebc8a0) over the last sum, then a correct trailer
head -c $((fsize - 12)) "$dir/f04.hfvs" > "$dir/big.body"
printf '\240\310\353\205\363\314\341\177' >> "$dir/big.body"
{ cat "$dir/big.body"; printf "$(crc32_le "$dir/big.body")"; } > "$dir/big.hfvs"
expect_fail "sum: 1e308 under a correct checksum" 1 sum "$dir/big.hfvs" -o "$o"
grep -q 'outside the domain' "$dir/stderr" && ok "sum: out-of-domain value named" || bad "sum: out-of-domain value named: $(cat "$dir/stderr")"
{ cat "$dir/f04.hfvs"; } > "$dir/same.hfvs"
head -c $((fsize - 4)) "$dir/f04.hfvs" > "$dir/same.body"
[ "$(printf "$(crc32_le "$dir/same.body")" | od -An -tx1)" = "$(tail -c 4 "$dir/f04.hfvs" | od -An -tx1)" ] &&
  ok "crc32_le agrees with the library" || bad "crc32_le agrees with the library"
printf 'old\n' > "$dir/keep.pfm"
"$hfvis" sum "$s0" "$s8" -o "$dir/keep.pfm" 2> /dev/null
[ "$(cat "$dir/keep.pfm")" = old ] && ok "refused sum keeps the old OUT" || bad "refused sum keeps the old OUT"
"$hfvis" help sum | grep -q 'PART.hfvs' && ok "help sum" || bad "help sum"

# ---- GIS conventions and commands ---------------------------------------------------------
# Angle flags in degrees, or radians with --radians; --convention compass (default), grass, grid.
expect_ok "horizon --azimuth 90 (compass: east)" "$dir/ae.pfm" horizon "$h" --azimuth 90 -o "$dir/ae.pfm"
expect_ok "horizon --azimuth 1.5707963267948966 --radians" "$dir/aer.pfm" horizon "$h" --azimuth 1.5707963267948966 --radians -o "$dir/aer.pfm"
cmp -s "$dir/ae.pfm" "$dir/aer.pfm" && ok "degrees = radians, bit for bit" || bad "degrees and radians differ"
expect_ok "horizon --convention grid --azimuth 0 (east)" "$dir/ag.pfm" horizon "$h" --convention grid --azimuth 0 -o "$dir/ag.pfm"
cmp -s "$dir/ae.pfm" "$dir/ag.pfm" && ok "compass 90 = grid 0" || bad "compass 90 differs from grid 0"
expect_ok "horizon --convention grass --azimuth 0 (east)" "$dir/as.pfm" horizon "$h" --convention grass --azimuth 0 -o "$dir/as.pfm"
cmp -s "$dir/ae.pfm" "$dir/as.pfm" && ok "compass 90 = grass 0" || bad "compass 90 differs from grass 0"
expect_ok "horizon --convention grass --azimuth 90 (north)" "$dir/an.pfm" horizon "$h" --convention grass --azimuth 90 -o "$dir/an.pfm"
expect_ok "horizon --azimuth 0 (compass: north)" "$dir/an2.pfm" horizon "$h" --azimuth 0 -o "$dir/an2.pfm"
cmp -s "$dir/an.pfm" "$dir/an2.pfm" && ok "grass 90 = compass 0" || bad "grass 90 differs from compass 0"
expect_ok "horizon --convention grid --azimuth -90 (north)" "$dir/an3.pfm" horizon "$h" --convention grid --azimuth -90 -o "$dir/an3.pfm"
cmp -s "$dir/an.pfm" "$dir/an3.pfm" && ok "grid -90 = compass 0" || bad "grid -90 differs from compass 0"
expect_ok "shadow --radians" "$dir/shr.pfm" shadow "$h" --sun-azimuth 3.9269908169872414 --sun-elevation 0.17453292519943295 --radians -o "$dir/shr.pfm"
expect_ok "shadow degrees" "$dir/shd.pfm" shadow "$h" --sun-azimuth 225 --sun-elevation 10 -o "$dir/shd.pfm"
same_or_ulp "shadow: degrees = radians" "$dir/shd.pfm" "$dir/shr.pfm"
# --split: one file per direction named by its azimuth; compass planes run clockwise from north,
# grass planes counter-clockwise from east, so compass _090 (east) is grass _000 and compass _000
# (north) is grass _090.
expect_ok "horizon --split (compass)" "$dir/hs_000.pfm" horizon "$h" --dirs 4 --split -o "$dir/hs.pfm"
for b in 090 180 270; do [ -s "$dir/hs_$b.pfm" ] && ok "--split wrote hs_$b.pfm" || bad "--split: no hs_$b.pfm"; done
[ ! -e "$dir/hs.pfm" ] && ok "--split writes no stack" || bad "--split wrote the stack"
expect_ok "horizon --split --convention grass" "$dir/hg_000.pfm" horizon "$h" --dirs 4 --split --convention grass -o "$dir/hg.pfm"
cmp -s "$dir/hs_090.pfm" "$dir/hg_000.pfm" && ok "east: compass _090 = grass _000" || bad "compass _090 differs from grass _000"
cmp -s "$dir/hs_000.pfm" "$dir/hg_090.pfm" && ok "north: compass _000 = grass _090" || bad "compass _000 differs from grass _090"
cmp -s "$dir/hs_000.pfm" "$dir/an2.pfm" && ok "--split plane = --azimuth run" || bad "--split plane differs from the --azimuth run"
expect_ok "horizon --split 16 directions, PGM" "$dir/hp_022_500.pgm" horizon "$h" --dirs 16 --split -o "$dir/hp.pgm"
[ -s "$dir/hp_337_500.pgm" ] && ok "--split names 337.5 as _337_500" || bad "--split: no hp_337_500.pgm"
expect_ok "horizon grass --azimuth 180 (west)" "$dir/hg1.pfm" horizon "$h" --convention grass --azimuth 180 -o "$dir/hg1.pfm"
cmp -s "$dir/hg_180.pfm" "$dir/hg1.pfm" && ok "grass _180 = --azimuth 180 (west)" || bad "grass _180 differs"
expect_fail "--math is gone, loudly" 2 shadow "$h" --math --sun-azimuth 1 --sun-elevation 1 -o "$o"
expect_fail "--convention math" 2 skyview "$h" --convention math -o "$o"
expect_fail "--convention foo" 2 skyview "$h" --convention foo -o "$o"
expect_fail "--azimuth with --dirs 4" 2 horizon "$h" --azimuth 10 --dirs 4 -o "$o"
expect_fail "--azimuth with --azimuth0" 2 horizon "$h" --azimuth 10 --azimuth0 3 -o "$o"
expect_fail "--split with --dir-range" 2 horizon "$h" --split --dir-range 0:4 -o "$fdir/x.hfvs"
expect_fail "--sun-elevation 2 rad" 2 shadow "$h" --sun-azimuth 1 --sun-elevation 2 --radians -o "$o"
expect_fail "--compass with --convention grass" 2 skyview "$h" --convention grass --compass -o "$o"

# V valley z = |x - 20| on 41 x 41 (cell 1): closed forms for hillshade, SAGA's SVF and openness
# (checked on the last row and at the centre, 841 floats before the end).
awk 'BEGIN { print "P2 41 41 255"; for (y = 0; y < 41; y++) { s = ""; for (x = 0; x < 41; x++) s = s " " (x < 20 ? 20 - x : x - 20); print s } }' > "$dir/vv.pgm"
# hillshade: sun in the east, tan(elevation) = 1/2. The west slope (normal (1,0,1)/sqrt2) gets
# n.l = (cos e + sin e)/sqrt2 = 0.948683 where lit; a point a cells west of the floor sees the
# east rim 20 cells east of the floor at tan = (20 - a)/(20 + a): in shadow for a <= 6 and on the
# floor; the east slope faces away (0).
expect_ok "hillshade V valley" "$dir/hv.pfm" hillshade "$dir/vv.pgm" --sun-azimuth 90 --sun-elevation 26.565051177077990 -o "$dir/hv.pfm"
expect_floats "hillshade V valley: lit x <= 13, cast shadow 14..20" "$dir/hv.pfm" 164 1e-5 \
  0.948683 0.948683 0.948683 0.948683 0.948683 0.948683 0.948683 0.948683 0.948683 0.948683 \
  0.948683 0.948683 0.948683 0.948683 0 0 0 0 0 0 0 0 0
expect_ok "hillshade V valley --no-shadows --blend 2" "$dir/hv2.pfm" hillshade "$dir/vv.pgm" --sun-azimuth 90 --sun-elevation 26.565051177077990 --no-shadows --blend 2 -o "$dir/hv2.pfm"
expect_floats "hillshade --blend 2 (east + west) without shadows: half of each slope's n.l" "$dir/hv2.pfm" 88 1e-5 \
  0.474342 0.447214 0.474342 0.474342 0.474342
expect_ok "hillshade flat, 4 suns, soft" "$dir/hf.pfm" hillshade "$f" --blend 4 --sun-radius 0.27 -o "$dir/hf.pfm"
expect_floats "hillshade flat = sin 45 deg" "$dir/hf.pfm" 8 1e-6 0.707107 0.707107
# SAGA's SVF with K = 4 (axis directions: the sweep is exact there). On the valley floor (the
# centre) the horizons are 0 (N, S) and 45 deg (E, W): saga 1 - (1/4)(1/2 + 1/2) = 0.75, visible
# (1/4)(1 + 1/2 + 1 + 1/2) = 0.75, Zaksek 1 - (1/4)(2 sin 45) = 0.646447. On the west slope 10 cells
# from the floor (normal (1,0,1)/sqrt2, 851 floats before the end): N, S 0, W 45 deg, E atan(1/3)
# (the far rim): saga (1/4)[2 n_z + n_z cos^2 phi_E + n_x (pi/2 - phi_E - sin cos) + n_z/2
# - n_x (pi/4 - 1/2)] = 0.718358 (the slope term of SAGA's formula), visible 0.823792,
# Zaksek 0.744166.
expect_ok "skyview --svf saga" "$dir/sv_saga.pfm" skyview "$dir/vv.pgm" --dirs 4 --svf saga -o "$dir/sv_saga.pfm"
expect_floats "skyview --svf saga, valley floor" "$dir/sv_saga.pfm" 3364 1e-6 0.75
expect_floats "skyview --svf saga, west slope" "$dir/sv_saga.pfm" 3404 1e-6 0.718358
expect_ok "skyview --svf visible" "$dir/sv_vis.pfm" skyview "$dir/vv.pgm" --dirs 4 --svf visible -o "$dir/sv_vis.pfm"
expect_floats "skyview --svf visible, valley floor" "$dir/sv_vis.pfm" 3364 1e-6 0.75
expect_floats "skyview --svf visible, west slope" "$dir/sv_vis.pfm" 3404 1e-6 0.823792
expect_ok "skyview (Zaksek)" "$dir/sv_z.pfm" skyview "$dir/vv.pgm" --dirs 4 -o "$dir/sv_z.pfm"
expect_floats "skyview Zaksek, valley floor" "$dir/sv_z.pfm" 3364 1e-6 0.646447
expect_floats "skyview Zaksek, west slope" "$dir/sv_z.pfm" 3404 1e-6 0.744166
expect_ok "skyview --svf saga flat" "$dir/sv_sf.pfm" skyview "$f" --svf saga -o "$dir/sv_sf.pfm"
expect_floats "skyview --svf saga flat = 1" "$dir/sv_sf.pfm" 8 1e-6 1 1
expect_fail "--svf saga with --dir-range" 2 skyview "$h" --svf saga --dir-range 0:4 -o "$fdir/x.hfvs"
# openness on the valley floor: K = 8 within 5 cells (the ray march; diagonals rise at
# atan(1/sqrt2) = 35.2644 deg): positive 90 - (2*45 + 4*35.2644)/8 = 61.1178 deg, negative
# 90 + 28.8822 = 118.8822 deg; unlimited (the sweep), K = 4: 90 - 90/4 = 67.5 deg.
expect_ok "openness --radius 5" "$dir/op5.pfm" openness "$dir/vv.pgm" --radius 5 --degrees -o "$dir/op5.pfm"
expect_floats "openness positive, radius 5, valley floor" "$dir/op5.pfm" 3364 1e-3 61.1178
expect_ok "openness unlimited" "$dir/op0.pfm" openness "$dir/vv.pgm" --dirs 4 --degrees -o "$dir/op0.pfm"
expect_floats "openness positive, unlimited, valley floor" "$dir/op0.pfm" 3364 1e-4 67.5
expect_ok "openness --negative --radius 5" "$dir/on5.pfm" openness "$dir/vv.pgm" --negative --radius 5 --degrees -o "$dir/on5.pfm"
expect_floats "openness negative, valley floor" "$dir/on5.pfm" 3364 1e-3 118.8822
expect_ok "openness flat, clamp" "$dir/opf.pfm" openness "$f" --radius 3 --border clamp -o "$dir/opf.pfm"
expect_floats "openness of a plane = pi/2" "$dir/opf.pfm" 8 1e-6 1.570796 1.570796

# viewshed: map coordinates (X = column * cell), the observer on NoData, --target, curvature.
expect_ok "viewshed --observer in map units" "$dir/vmap.pfm" viewshed "$h" --cell 2 --observer 7,4 -o "$dir/vmap.pfm"
expect_ok "viewshed --observer-grid" "$dir/vgrid.pfm" viewshed "$h" --cell 2 --observer-grid 3.5,2 -o "$dir/vgrid.pfm"
cmp -s "$dir/vmap.pfm" "$dir/vgrid.pfm" && ok "viewshed: map 7,4 at cell 2 = grid 3.5,2" || bad "viewshed map and grid observers differ"
expect_fail "viewshed observer on NoData" 1 viewshed "$dir/flat7.pgm" --nodata 7 --observer 0,0 -o "$o"
grep -q 'NoData' "$dir/stderr" && ok "viewshed: NoData observer named" || bad "viewshed: NoData observer not named"
expect_fail "viewshed observer outside" 1 viewshed "$f" --observer 8,0 -o "$o"
expect_fail "--refraction without --curvature" 2 viewshed "$f" --observer 0,0 --refraction 0.2 -o "$o"
# A flat 300 x 1 field, 100 m cells, eye 10 m up: the horizon is at sqrt(2 R h/(1 - k)) =
# 12102 m (k = 0.13) or 11288 m (k = 0): on the samples, the last visible one is column 121 (113).
awk 'BEGIN { print "P2 300 1 255"; for (x = 0; x < 300; x++) print 0 }' > "$dir/line.pgm"
expect_ok "viewshed flat, no curvature" "$dir/vc0.pfm" viewshed "$dir/line.pgm" --cell 100 --observer 0,0 --observer-height 10 -o "$dir/vc0.pfm"
expect_floats "viewshed flat without curvature sees everything" "$dir/vc0.pfm" 8 0 1 1
expect_ok "viewshed --curvature" "$dir/vc.pfm" viewshed "$dir/line.pgm" --cell 100 --observer 0,0 --observer-height 10 --curvature --target 12100,0 --target 12200,0 --target 99999,0 -o "$dir/vc.pfm"
expect_floats "viewshed --curvature (k = 0.13): horizon after column 121" "$dir/vc.pfm" 720 0 1 1 0 0
expect_stdout "viewshed --target visible" "target 12100,0 (column 121, row 0): visible"
expect_stdout "viewshed --target hidden" "target 12200,0 (column 122, row 0): hidden"
expect_stdout "viewshed --target outside: where it was given" "target 99999,0 (column 999.99, row 0): outside the grid"
expect_ok "viewshed --curvature --refraction 0" "$dir/vc00.pfm" viewshed "$dir/line.pgm" --cell 100 --observer 0,0 --observer-height 10 --curvature --refraction 0 --exact -o "$dir/vc00.pfm"
expect_floats "viewshed --curvature (k = 0): horizon after column 113" "$dir/vc00.pfm" 752 0 1 1 0 0

# PGM outputs: code 0 is NoData, 1..65535 the range, recorded in the header comment.
expect_ok "skyview PGM with a hole" "$dir/nd.pgm" skyview "$dir/flat7.pgm" --nodata 7 -o "$dir/nd.pgm"
[ "$(head -c 3 "$dir/nd.pgm" | od -An -c | tr -d ' ')" = 'P5\n' ] &&
  sed -n 2p "$dir/nd.pgm" | grep -qx '# hfvis range 0.00000000e+00 1.00000000e+00 nodata 0' &&
  ok "PGM range comment" || bad "PGM range comment: $(head -c 80 "$dir/nd.pgm" | tr '\n' '|')"
size=$(wc -c < "$dir/nd.pgm" | tr -d ' ')
first=$(od -An -tx1 -j $((size - 96)) -N 4 "$dir/nd.pgm" | tr -s ' ' | sed 's/^ //; s/ $//')
[ "$first" = "00 00 ff ff" ] && ok "PGM: NoData is code 0, SVF 1 is 65535" || bad "PGM NoData codes: '$first'"
expect_ok "horizon PGM --degrees south: -90 deg is code 1, not NoData" "$dir/hd.pgm" horizon "$f" --azimuth 180 --degrees -o "$dir/hd.pgm"
expect_bytes "horizon PGM: the open border (-90) is code 1" "$dir/hd.pgm" 2 "00 01"

# Never destroy an input: the same file through a hard link or a symbolic link is refused.
cp "$h" "$dir/in.pgm"; cp "$h" "$dir/in_copy.pgm"
ln "$dir/in.pgm" "$dir/in_hard.pgm" 2> /dev/null
ln -s "$dir/in.pgm" "$dir/in_sym.pgm" 2> /dev/null
expect_fail "same file as the input" 1 skyview "$dir/in.pgm" -o "$dir/in.pgm"
grep -q 'refusing to replace an input' "$dir/stderr" && ok "same-file refusal names the reason" || bad "same-file refusal message"
if [ -f "$dir/in_hard.pgm" ]; then expect_fail "output is a hard link to the input" 1 skyview "$dir/in.pgm" -o "$dir/in_hard.pgm"
else ok "hard link: skipped (no ln)"; fi
if [ -L "$dir/in_sym.pgm" ]; then expect_fail "output is a symbolic link to the input" 1 skyview "$dir/in.pgm" -o "$dir/in_sym.pgm"
else ok "symbolic link: skipped (no ln -s)"; fi
expect_fail "output is the albedo map" 1 indirect "$f" --albedo-map "$dir/alb51.pgm" -o "$dir/alb51.pgm"
cmp -s "$dir/in.pgm" "$dir/in_copy.pgm" && ok "refused runs leave the input intact" || bad "the input changed"
ln -s "$s0" "$dir/part_as_out.pfm" 2> /dev/null
if [ -L "$dir/part_as_out.pfm" ]; then expect_fail "sum: output is a part" 1 sum "$s0" "$s4" "$s8" "$s12" -o "$dir/part_as_out.pfm"
else ok "sum same file: skipped (no ln -s)"; fi
cp "$dir/vv.pgm" "$dir/ow.pgm"
if "$hfvis" hillshade "$dir/ow.pgm" --overwrite -o "$dir/ow.pgm" 2> "$dir/stderr" && ! cmp -s "$dir/ow.pgm" "$dir/vv.pgm"
then ok "--overwrite replaces the input"; else bad "--overwrite: $(cat "$dir/stderr")"; fi
# A replaced output loses its stale GDAL sidecar OUT.aux.xml (statistics of the old values), in
# every format, the library's codecs and the raster writers alike; a refused run keeps it.
for x in pfm pgm tif asc flt; do
  echo stale > "$dir/aux.$x.aux.xml"
  expect_ok "a .$x output" "$dir/aux.$x" skyview "$h" --dirs 4 -o "$dir/aux.$x"
  [ -e "$dir/aux.$x.aux.xml" ] && bad "a .$x output left its stale .aux.xml" || ok "a .$x output removed its stale .aux.xml"
done
cp "$h" "$dir/auxin.pgm"; echo stale > "$dir/auxin.pgm.aux.xml"
"$hfvis" skyview "$dir/auxin.pgm" -o "$dir/auxin.pgm" 2> /dev/null
[ -s "$dir/auxin.pgm.aux.xml" ] && ok "a refused run keeps OUT.aux.xml" || bad "a refused run removed OUT.aux.xml"

# --progress: plain lines with percent and ETA, and the summary line.
if "$hfvis" skyview "$h" --dirs 16 --progress -o "$dir/pr.pfm" > "$dir/stdout" 2> "$dir/stderr" &&
   grep -q '^hfvis skyview: 100% (16/16)' "$dir/stderr" &&
   grep -q '^hfvis skyview: done in [0-9.]* s: 480 cells, 16 directions -> ' "$dir/stderr" &&
   ! grep -q "$(printf '\r')" "$dir/stderr"
then ok "--progress lines and summary"; else bad "--progress: $(cat "$dir/stderr")"; fi
if "$hfvis" skyview "$h" --dirs 16 --progress --quiet -o "$dir/pr.pfm" 2> "$dir/stderr" && [ ! -s "$dir/stderr" ]
then ok "--quiet silences --progress"; else bad "--quiet with --progress: $(cat "$dir/stderr")"; fi
# --threads by default: the online cores, fewer where --max-memory cannot hold one run's estimate
# per thread; a given --threads N is kept. The estimate line names the threads; outputs are equal.
cores=$(getconf _NPROCESSORS_ONLN 2> /dev/null || echo 1); [ "$cores" -gt 256 ] && cores=256
thr() { sed -n 's/.*estimate \([0-9.e+-]*\) MiB.*, \([0-9]*\) threads*$/\1 \2/p' "$dir/stderr"; }
"$hfvis" skyview "$h" --dirs 16 --progress -o "$dir/th0.pfm" 2> "$dir/stderr"; r=$(thr)
est=${r% *}; n=${r#* }
[ "$n" = "$cores" ] && ok "--threads default: the $cores online cores" || bad "--threads default: '$n' threads, $cores cores: $(cat "$dir/stderr")"
"$hfvis" skyview "$h" --dirs 16 --threads 1 --quiet -o "$dir/th1.pfm" && cmp -s "$dir/th0.pfm" "$dir/th1.pfm" &&
  ok "--threads default equals --threads 1 byte for byte" || bad "--threads default differs from --threads 1"
if [ "$cores" -ge 2 ]; then
  cap=$(awk -v e="$est" 'BEGIN { printf "%dK", e * 1024 * 1.5 + 1 }')
  "$hfvis" skyview "$h" --dirs 16 --progress --max-memory "$cap" -o "$dir/th2.pfm" 2> "$dir/stderr"; r=$(thr)
  [ "${r#* }" = 1 ] && cmp -s "$dir/th2.pfm" "$dir/th1.pfm" &&
    ok "--threads default: one thread where --max-memory $cap holds one estimate ($est MiB), not two" ||
    bad "--threads default under --max-memory $cap: '$r': $(cat "$dir/stderr")"
  "$hfvis" skyview "$h" --dirs 16 --progress --threads 2 --max-memory "$cap" -o "$dir/th2.pfm" 2> "$dir/stderr"; r=$(thr)
  [ "${r#* }" = 2 ] && ok "--threads 2 given is kept under --max-memory" || bad "--threads 2 under --max-memory $cap: '$r'"
else
  echo "SKIP --threads cap: one online core"
fi

# A PFM of more than one band of rows is written by the run's threads (each slice at its place,
# pwrite): the file is the one-thread file byte for byte, for planes (a horizon map, 320 rows,
# the last band short) and for three channels (environment light of a 24 x 150 grid)
LC_ALL=C awk 'BEGIN { w = 24; h = 150; print "P2"; print w, h; print 255
  for (y = 0; y < h; y++) { s = ""; for (x = 0; x < w; x++) s = s " " int(128 + 100 * sin(x / 3) * cos(y / 4)); print s } }' > "$dir/tall.pgm"
for t in 1 2 3; do
  "$hfvis" horizon "$h" --dirs 16 --threads $t --quiet -o "$dir/pw_h$t.pfm" &&
  "$hfvis" light "$dir/tall.pgm" --env "$dir/env3.pfm" --dirs 8 --threads $t --quiet -o "$dir/pw_n$t.pfm" || bad "PFM by threads: --threads $t failed"
done
sz=$(wc -c < "$dir/pw_h2.pfm" | tr -d ' ')
cmp -s "$dir/pw_h1.pfm" "$dir/pw_h2.pfm" && cmp -s "$dir/pw_h1.pfm" "$dir/pw_h3.pfm" && [ "$sz" = $((15 + 24 * 320 * 4)) ] &&
  ok "PFM written by 2 and 3 threads (horizon, 320 rows) equals one thread's byte for byte" ||
  bad "PFM written by threads (horizon) differs from one thread's (size $sz)"
cmp -s "$dir/pw_n1.pfm" "$dir/pw_n2.pfm" && cmp -s "$dir/pw_n1.pfm" "$dir/pw_n3.pfm" &&
  ok "PFM written by 2 and 3 threads (light, 3 channels, 150 rows) equals one thread's byte for byte" ||
  bad "PFM written by threads (light, 3 channels) differs from one thread's"

# A failed summary never follows a replaced OUT (issue: `visibility --stats > /dev/full` exited 1
# after renaming the new file over OUT): the counters are printed first, OUT is then untouched.
if [ -w /dev/full ]; then
  printf 'old\n' > "$dir/old.pfm"
  "$hfvis" visibility "$h" --dirs 4 --cell 1 --stats -o "$dir/old.pfm" > /dev/full 2> "$dir/stderr"; rc=$?
  [ "$rc" -eq 1 ] && [ "$(cat "$dir/old.pfm")" = old ] && [ "$(wc -l < "$dir/stderr" | tr -d ' ')" = 1 ] &&
    ok "visibility --stats > /dev/full: exit 1, OUT untouched" || bad "visibility --stats > /dev/full: exit $rc, OUT $(head -c 2 "$dir/old.pfm")"
else
  ok "visibility --stats > /dev/full: SKIP (no /dev/full)"
fi
# visfield build enforces its extension (issue: HFVF data went into x.pfm or field.txt, exit 0)
expect_fail "visfield build -o x.pfm" 2 visfield "$dir/cube.obj" --positions 82 --dirs 4 -o "$fdir/x.pfm"
expect_fail "visfield build -o field.txt" 2 visfield "$dir/cube.obj" --positions 82 --dirs 4 -o "$fdir/field.txt"
# the flag at fault is named (issue: "ssao: HFVIS_ERR_INVALID_ARGUMENT")
expect_fail "ssao --dirs 5000" 2 ssao "$dir/plane.pfm" --method lsao --dirs 5000 -o "$o"
grep -q -- '--dirs' "$dir/stderr" && ok "ssao --dirs named" || bad "ssao --dirs named: $(cat "$dir/stderr")"
expect_fail "ssao ffao --dirs 2" 2 ssao "$dir/plane.pfm" --method ffao --dirs 2 -o "$o"
# light --env with NaN or negative radiance is refused, as gi does
{ printf 'Pf\n4 2\n-1\n'; printf "$nan"; i=1; while [ $i -lt 8 ]; do printf "$one"; i=$((i + 1)); done; } > "$dir/envnan.pfm"
{ printf 'Pf\n4 2\n-1\n'; printf "$mone"; i=1; while [ $i -lt 8 ]; do printf "$one"; i=$((i + 1)); done; } > "$dir/envneg.pfm"
expect_fail "light --env with NaN" 1 light "$h" --env "$dir/envnan.pfm" -o "$o"
expect_fail "light --env negative" 1 light "$h" --env "$dir/envneg.pfm" -o "$o"
grep -q 'radiance' "$dir/stderr" && ok "light --env: radiance named" || bad "light --env: radiance named"
# help texts: no literal %%, meshao's --size range as enforced, duplicates and links documented
if "$hfvis" --help 2>&1 | grep -q '%%' || "$hfvis" ssao --help | grep -q '%%' || "$hfvis" viewshed --help | grep -q '%%'
then bad "help: a literal %%"; else ok "help: no literal %%"; fi
for c in horizon skyview sky shadow light normals indirect visibility viewshed voxelize gi ssao volgi visfield meshao; do
  "$hfvis" "$c" --help | grep -q '%%' && bad "help $c: a literal %%"
done
"$hfvis" meshao --help | grep -q '1..32768 each' && ok "help meshao: --size range" || bad "help meshao: --size range"
expect_ok "meshao --size 16384x1 (as documented)" "$dir/m.pfm" meshao "$dir/cube.obj" --size 16384x1 --rays 1 -o "$dir/m.pfm"
"$hfvis" skyview --help | grep -q 'given twice' && ok "help: duplicated options documented" || bad "help: duplicated options documented"
"$hfvis" skyview --help | grep -q 'symbolic link' && ok "help: symbolic links documented" || bad "help: symbolic links documented"

# Tiny cells and huge scales are computed scale-free or refused with the flag named (issue:
# --cell 1e-50 gave NaN with exit 0, --zscale 3e38 turned samples into holes silently)
expect_ok "skyview --cell 1e-50" "$dir/c.pfm" skyview "$h" --cell 1e-50 -o "$dir/c.pfm"
expect_ok "sky --cell 1e-50" "$dir/c.pfm" sky "$h" --cell 1e-50 -o "$dir/c.pfm"
expect_ok "normals --cell 1e-100" "$dir/c.pfm" normals "$h" --cell 1e-100 -o "$dir/c.pfm"
expect_fail "--cell 1e-160 (ratio past 1e150)" 1 skyview "$h" --cell 1e-160 -o "$o"
grep -q -- '--cell' "$dir/stderr" && ok "--cell named" || bad "--cell named"
expect_fail "--zscale 3e38" 1 skyview "$h" --zscale 3e38 -o "$o"
grep -q -- '--zscale' "$dir/stderr" && ok "--zscale named" || bad "--zscale named"
# The heights' pass runs by blocks of 2^18 values over the threads: the cell named is the first
# whose scaled height overflows, in the second block here (file value 263000 of 600 x 440, rows
# stored bottom first: cell (200, 1)); the value 2e38 after it in the same block and a NaN before.
{ printf 'Pf\n600 440\n-1\n'; head -c 1048000 /dev/zero; printf '\000\000\300\177'; head -c 3996 /dev/zero
  printf '\231\166\026\177'; printf '\231\166\026\177'; head -c 3992 /dev/zero; } > "$dir/overflow.pfm"
for t in 1 2; do
  expect_fail "--zscale 2 over two blocks, $t thread(s)" 1 skyview "$dir/overflow.pfm" --zscale 2 --threads $t --dirs 4 -o "$o"
  grep -q 'value 2e+38 at (200, 1) exceeds' "$dir/stderr" && ok "--zscale: the first overflowing cell named ($t)" \
    || bad "--zscale: first overflowing cell: $(cat "$dir/stderr")"
done
expect_ok "--zscale 1.5 on the same file" "$dir/ovok.pfm" skyview "$dir/overflow.pfm" --zscale 1.5 --dirs 4 -o "$dir/ovok.pfm"
expect_fail "--sky 3e38 --albedo 3e38" 2 sky "$h" --sky 3e38 --albedo 3e38 -o "$o"
# Light inputs each within the float range whose product is not (issue: an emission map of 3e38
# under --sky 3e38 wrote an all-NaN raster with exit 0): the result is checked, nothing written
huge='\346\261\141\177' # 3e38f little-endian
{ printf 'Pf\n8 6\n-1\n'; i=0; while [ $i -lt 48 ]; do printf "$huge"; i=$((i + 1)); done; } > "$dir/huge.pfm"
awk 'BEGIN { print "P2 8 6 255"; for (i = 0; i < 48; i++) print (i % 8) * (i % 8) * 3 }' > "$dir/hill8.pgm"
expect_fail "indirect --emission 3e38 --sky 3e38" 1 indirect "$dir/flat.pgm" --emission "$dir/huge.pfm" --sky 3e38 --bounces 2 -o "$o"
grep -q 'overflow the float range' "$dir/stderr" && ok "indirect overflow named" || bad "indirect overflow named"
expect_fail "indirect --albedo-map 3e38" 1 indirect "$dir/hill8.pgm" --albedo-map "$dir/huge.pfm" --bounces 2 -o "$o"
expect_fail "gi --specular 3e38" 1 gi "$h" --specular 3e38 -o "$o"
expect_fail "light --env 3e38 --albedo 3e38" 1 light "$dir/flat.pgm" --env "$dir/envhuge.pfm" --albedo 3e38 -o "$o"
"$hfvis" light "$h" --env "$dir/envhuge.pfm" --albedo 3e38 --dir-range 0:8 -o "$dir/ph1.hfvs" 2> /dev/null &&
"$hfvis" light "$h" --env "$dir/envhuge.pfm" --albedo 3e38 --dir-range 8:16 -o "$dir/ph2.hfvs" 2> /dev/null &&
  ok "light parts of a too-bright run (their sums are finite)" || bad "light parts of a too-bright run"
expect_fail "sum of too-bright light parts" 1 sum "$dir/ph1.hfvs" "$dir/ph2.hfvs" -o "$o"
expect_ok "indirect --emission 1 (in range)" "$dir/c.pfm" indirect "$dir/flat.pgm" --emission "$dir/emit1.pfm" --bounces 2 -o "$dir/c.pfm"

# Costs up front (issue: a 16 KB 1 x 16384 PGM made skyview allocate 2.1 GB; volgi --res 256
# --iterations 1048576 ran with no estimate): --max-memory refuses before allocating and names
# the estimate; the help states the viewshed's true cost
awk 'BEGIN { print "P2 1 16384 255"; for (i = 0; i < 16384; i++) print 0 }' > "$dir/thin.pgm"
expect_fail "skyview 1 x 16384 over --max-memory 100M" 1 skyview "$dir/thin.pgm" --max-memory 100M -o "$o"
grep -q 'needs about' "$dir/stderr" && ok "--max-memory: the estimate is named" || bad "--max-memory: the estimate is named"
# the estimate counts the output's channels, read from the maps' headers before they are loaded:
# an RGB environment or emission map needs more than a grey one
mib() { sed -n 's/.*needs about \([0-9.e+-]*\) MiB.*/\1/p' "$dir/stderr"; }
expect_fail "light, grey env, over --max-memory 1K" 1 light "$h" --env "$dir/env1.pfm" --max-memory 1K -o "$o"; m1=$(mib)
expect_fail "light, RGB env, over --max-memory 1K" 1 light "$h" --env "$dir/env3.pfm" --max-memory 1K -o "$o"; m3=$(mib)
awk -v a="$m1" -v b="$m3" 'BEGIN { exit !(a > 0 && b > 1.2 * a) }' &&
  ok "estimate: RGB light $m3 MiB > grey $m1 MiB" || bad "estimate: RGB light '$m3' MiB not above grey '$m1' MiB"
expect_fail "indirect, grey, over --max-memory 1K" 1 indirect "$f" --albedo 0.5 --max-memory 1K -o "$o"; m1=$(mib)
expect_fail "indirect, RGB emission, over --max-memory 1K" 1 indirect "$f" --emission "$dir/emit3.pfm" --max-memory 1K -o "$o"; m3=$(mib)
awk -v a="$m1" -v b="$m3" 'BEGIN { exit !(a > 0 && b > 1.2 * a) }' &&
  ok "estimate: RGB indirect $m3 MiB > grey $m1 MiB" || bad "estimate: RGB indirect '$m3' MiB not above grey '$m1' MiB"
expect_fail "volgi 256^3 x 2^20 over --max-memory 512M" 1 volgi --room --res 256 --iterations 1048576 --max-memory 512M -o "$o"
expect_fail "--max-memory 1X" 2 skyview "$h" --max-memory 1X -o "$o"
expect_ok "--max-memory 0 (no limit)" "$dir/mm.pfm" skyview "$h" --max-memory 0 -o "$dir/mm.pfm"
expect_ok "--max-memory 64M" "$dir/mm.pfm" skyview "$h" --max-memory 64M -o "$dir/mm.pfm"
"$hfvis" viewshed --help | grep -q 'O((W + H) \* max(W, H))' && ok "help viewshed: its cost" || bad "help viewshed: its cost"
"$hfvis" skyview --help | grep -q 'max-memory' && ok "help: --max-memory" || bad "help: --max-memory"

# An interrupt during a real write (issue: SIGINT/SIGTERM while a 4096^2 horizon was written
# left its 354 MB temporary file): the 48 MB write of `normals` on 2048 x 2048 zeros is started
# in the foreground (a background job would have SIGINT ignored), a poller signals it as soon as
# its temporary file exists: no temporary file may remain, and OUT is absent (exit 128 + the
# signal number) or, where the write and rename beat the signal, whole.
sigdir=$dir/sig; mkdir -p "$sigdir"
{ printf 'Pf\n2048 2048\n-1\n'; head -c 16777216 /dev/zero; } > "$dir/zero2048.pfm"
"$hfvis" normals "$dir/zero2048.pfm" -o "$dir/nref.pfm" 2> /dev/null || bad "normals of 2048^2 zeros failed"
for sig in INT TERM HUP; do
  rm -f "$dir/sig.pid" "$dir/sig.caught"
  ( i=0; while [ ! -s "$dir/sig.pid" ] && [ $i -lt 200000 ]; do i=$((i + 1)); done
    i=0
    while [ $i -lt 1000000 ]; do
      for t in "$sigdir"/n.pfm.tmp*; do
        if [ -e "$t" ]; then kill -"$sig" "$(cat "$dir/sig.pid")"; : > "$dir/sig.caught"; exit 0; fi
      done
      i=$((i + 1))
    done ) &
  poller=$!
  sh -c 'echo $$ > "$1"; exec "$2" normals "$3" -o "$4"' sh "$dir/sig.pid" "$hfvis" "$dir/zero2048.pfm" "$sigdir/n.pfm" 2> /dev/null
  rc=$?
  wait "$poller"
  temps=$(ls "$sigdir" | grep -c '\.tmp' || true)
  if [ ! -f "$dir/sig.caught" ]; then bad "SIG$sig during a write: the temporary file was never seen"
  elif [ "$temps" -ne 0 ]; then bad "SIG$sig during a write: left $(ls "$sigdir")"
  elif [ -e "$sigdir/n.pfm" ]; then
    # the write and the rename finished before the signal arrived (a fast disk): then OUT must be
    # the whole file, never a part of it
    cmp -s "$sigdir/n.pfm" "$dir/nref.pfm" && ok "SIG$sig during a write: arrived after the file was published (exit $rc), OUT whole" ||
      bad "SIG$sig during a write: exit $rc with a partial n.pfm"
  elif [ "$rc" -le 128 ]; then bad "SIG$sig during a write: exit $rc without OUT"
  else ok "SIG$sig during a write: exit $rc, directory clean"; fi
  rm -f "$sigdir"/*
done
rm -f "$dir/zero2048.pfm" "$dir/nref.pfm"

# Legal long names (issue: the 12-byte temporary suffix made a 244-byte name fail, ENAMETOOLONG)
long=$(awk 'BEGIN { for (i = 0; i < 247; i++) printf "%c", 97 + i % 26 }').pfm
expect_ok "a 251-byte output name" "$dir/$long" skyview "$dir/flat.pgm" --dirs 4 -o "$dir/$long"
rm -f "$dir/$long"
# the same through the streaming writer of GeoTIFF and ASCII-grid outputs (it once had its own
# temporary names, without the cut)
longt=$(awk 'BEGIN { for (i = 0; i < 247; i++) printf "%c", 97 + i % 26 }').tif
expect_ok "a 251-byte GeoTIFF output name" "$dir/$longt" skyview "$dir/flat.pgm" --dirs 4 -o "$dir/$longt"
rm -f "$dir/$longt"
longa=$(awk 'BEGIN { for (i = 0; i < 247; i++) printf "%c", 97 + i % 26 }').asc
expect_ok "a 251-byte ASCII grid output name" "$dir/$longa" skyview "$dir/flat.pgm" --dirs 4 -o "$dir/$longa"
rm -f "$dir/$longa"

# ---- +-Inf heights are holes (hfvis.h), not a --cell refusal; --max-memory is checked against
# the header's size before the heights are read (a 16000 x 16000 PFM header over a sparse file,
# under a 300 MB address-space limit: the refusal, never an out-of-memory) --------------------
inf='\000\000\200\177'; minf='\000\000\200\377'
{ printf 'Pf\n3 2\n-1\n'; printf "$inf$one$one$one$minf$one"; } > "$dir/inf.pfm"
"$hfvis" skyview "$dir/inf.pfm" --cell 1 --dirs 4 -o "$dir/inf_svf.pfm" > /dev/null 2> "$dir/err"; rc=$?
[ "$rc" -eq 0 ] && [ ! -s "$dir/err" ] && [ -s "$dir/inf_svf.pfm" ] \
  && ok "+-Inf heights are holes: exit 0, no message" || bad "+-Inf heights: exit $rc: $(cat "$dir/err")"
{ printf 'Pf\n2 1\n-1\n'; printf "$inf$inf"; } > "$dir/allinf.pfm"
"$hfvis" skyview "$dir/allinf.pfm" --dirs 4 -o "$dir/x.pfm" > /dev/null 2> "$dir/err"
grep -q -- '^hfvis: --cell' "$dir/err" && bad "an all-Inf raster blames --cell: $(cat "$dir/err")" || ok "an all-Inf raster does not blame --cell"
rm -f "$dir/x.pfm"
printf 'Pf\n16000 16000\n-1\n' > "$dir/huge.pfm"
if dd if=/dev/zero of="$dir/huge.pfm" bs=1 count=1 seek=1024000017 conv=notrunc 2> /dev/null; then
  # 300 MB of address space proves nothing is committed; a sanitizer build reserves terabytes of
  # shadow memory up front, so it runs without that limit (the refusal is checked the same)
  case "$CFLAGS" in *-fsanitize*) vlimit=unlimited ;; *) vlimit=300000 ;; esac
  ( ulimit -v $vlimit; exec "$hfvis" skyview "$dir/huge.pfm" --max-memory 10M -o "$dir/fail/h.pfm" ) > /dev/null 2> "$dir/err"; rc=$?
  [ "$rc" -eq 1 ] && grep -q 'over --max-memory' "$dir/err" && [ "$(wc -l < "$dir/err" | tr -d ' ')" = 1 ] \
    && ok "--max-memory refuses from the header, before loading 1 GB: $(cat "$dir/err")" \
    || bad "--max-memory on a 16000^2 header: exit $rc: $(head -n 2 "$dir/err")"
else echo "SKIP cannot make a sparse 1 GB file (--max-memory before loading)"; fi
rm -f "$dir/huge.pfm"

# ---- a file-size limit (ulimit -f, SIGXFSZ ignored: the write fails with EFBIG, as on a full
# disk): every output format exits 1 with one line, the previous output (and its sidecars) stays
# byte for byte, and no temporary file is left ----------------------------------------------
awk 'BEGIN { w = 100; h = 100; print "P2"; print w, h; print 65535
  for (y = 0; y < h; y++) { s = ""; for (x = 0; x < w; x++) s = s " " int(30000 + 9000 * sin(x * 0.7) * cos(y * 0.45) + (x * 37 + y * 91) % 997); print s } }' > "$dir/noisy.pgm"
mkdir -p "$dir/fsz"
for ext in pfm pgm tif asc flt bil; do
  rm -f "$dir/fsz/"*
  if "$hfvis" skyview "$dir/noisy.pgm" --cell 1 --dirs 4 -o "$dir/fsz/o.$ext" > /dev/null 2>&1; then
    mkdir -p "$dir/fsz_old"; rm -f "$dir/fsz_old/"*; cp "$dir/fsz/"* "$dir/fsz_old/"
    ( trap '' XFSZ; ulimit -f 8; exec "$hfvis" skyview "$dir/noisy.pgm" --cell 1 --dirs 8 -o "$dir/fsz/o.$ext" ) > /dev/null 2> "$dir/err"; rc=$?
    same=1; for f in "$dir/fsz_old/"*; do cmp -s "$f" "$dir/fsz/$(basename "$f")" || same=0; done
    n_old=$(ls "$dir/fsz_old" | wc -l); n_new=$(ls "$dir/fsz" | wc -l)
    if [ "$rc" -eq 1 ] && [ "$(wc -l < "$dir/err" | tr -d ' ')" = 1 ] && [ "$same" = 1 ] && [ "$n_old" = "$n_new" ]; then
      ok "file-size limit, .$ext: exit 1, one line, the old output intact, no temporary file: $(cat "$dir/err")"
    else bad "file-size limit, .$ext: exit $rc, same $same, files $n_old -> $n_new: $(head -n 2 "$dir/err")"; fi
  else bad "file-size limit, .$ext: the unlimited run failed"; fi
done
rm -f "$dir/fsz/"*
( trap '' XFSZ; ulimit -f 8; exec "$hfvis" voxelize "$dir/cube.obj" --res 80 --mode solid -o "$dir/fsz/v.raw" ) > /dev/null 2> "$dir/err"; rc=$?
[ "$rc" -eq 1 ] && [ -z "$(ls "$dir/fsz")" ] && ok "file-size limit, voxelize .raw: exit 1, nothing left: $(cat "$dir/err")" \
  || bad "file-size limit, voxelize .raw: exit $rc, left $(ls "$dir/fsz")"
# ---- --threads: every split command's output is the one-thread run's byte for byte ------------
# rough.pgm: 61 x 53 ridges with a one-cell wall and NoData holes (value 0, --nodata 0)
awk 'BEGIN { w = 61; h = 53; print "P2"; print w, h; print 65535
  for (y = 0; y < h; y++) { s = ""; for (x = 0; x < w; x++) {
    v = int(30000 + 9000 * sin(x / 4.3) * cos(y / 3.1) + 4000 * sin((x + 2 * y) / 2.2))
    if (x == 30) v += 20000; if ((x * 7 + y * 13) % 97 == 0) v = 0; s = s " " v }; print s } }' > "$dir/rough.pgm"
r=$dir/rough.pgm
# thr_equal FIELD LABEL: each "name|command and flags" line of stdin run on FIELD with --threads
# 1, 2 and 3; the three outputs must be equal byte for byte
thr_equal() {
  while IFS='|' read -r name args; do
    [ -n "$name" ] || continue
    # shellcheck disable=SC2086 # $args is a list of flags
    for t in 1 2 3; do "$hfvis" $args "$1" --nodata 0 --cell 3 --quiet --threads $t -o "$dir/thr$t.pfm" 2> "$dir/terr" || break; done
    if [ -s "$dir/thr3.pfm" ] && cmp -s "$dir/thr1.pfm" "$dir/thr2.pfm" && cmp -s "$dir/thr1.pfm" "$dir/thr3.pfm"; then ok "--threads 1/2/3 equal$2: $name"
    else bad "--threads 1/2/3 differ or fail$2: $name $(cat "$dir/terr")"; fi
    rm -f "$dir"/thr?.pfm
  done
}
thr_equal "$r" "" <<EOF
horizon K=16|horizon --dirs 16
horizon K=10|horizon --dirs 10 --convention grass
horizon exact|horizon --dirs 12 --exact
skyview K=16|skyview --dirs 16
skyview K=7|skyview --dirs 7 --azimuth0 10
skyview exact|skyview --dirs 16 --exact
skyview exact radius clamp|skyview --dirs 20 --exact --max-distance 40 --border clamp
skyview radius clamp|skyview --dirs 16 --max-distance 40 --border clamp
sky|sky --dirs 16 --sky 2 --albedo 0.5
sky exact|sky --dirs 8 --exact
light rgb|light --dirs 8 --env $dir/env3.pfm
light exact|light --dirs 12 --exact --env $dir/env1.pfm
shadow|shadow --sun-azimuth 315 --sun-elevation 10
shadow exact disc|shadow --sun-azimuth 100 --sun-elevation 5 --exact --sun-radius 0.27
hillshade|hillshade --sun-azimuth 315 --sun-elevation 15
hillshade lattice blend|hillshade --lattice --blend 3
openness both|openness --radius 20 --both
openness clamp|openness --radius 12 --border clamp --negative
EOF
# tall.pgm: 97 x 203, taller than the tool's row bands (64 rows: the shared normals, the finish
# of the sums, split over the threads), so that bands, a short last band and their seams run
awk 'BEGIN { w = 97; h = 203; print "P2"; print w, h; print 65535
  for (y = 0; y < h; y++) { s = ""; for (x = 0; x < w; x++) {
    v = int(30000 + 9000 * sin(x / 5.1) * cos(y / 4.3) + 3000 * sin((x + 3 * y) / 2.7))
    if (y == 64 || y == 127) v += 15000; if ((x * 11 + y * 5) % 89 == 0) v = 0; s = s " " v }; print s } }' > "$dir/tall.pgm"
thr_equal "$dir/tall.pgm" ", row bands" <<EOF
skyview K=8|skyview --dirs 8
sky K=8|sky --dirs 8 --sky 3
sky exact|sky --dirs 8 --exact
light rgb|light --dirs 4 --env $dir/env3.pfm
horizon K=8|horizon --dirs 8
shadow|shadow --sun-azimuth 200 --sun-elevation 8
EOF
# PFM outputs are written in slices of about 8 MB (examples/cli/write.c): a 2400 x 1000 normals
# map (28,800 bytes a row, 291 rows a slice: 4 slices) has the whole image's header and size,
# the bottom row first (here sloped along x: its first value is not 0) and the top row last (flat:
# its normals' first component is 0)
awk 'BEGIN { w = 2400; h = 1000; print "P2"; print w, h; print 65535
  for (y = 0; y < h; y++) { s = ""; for (x = 0; x < w; x++) s = s " " (y < 500 ? 100 : 100 + 20 * x); print s } }' > "$dir/slope.pgm"
if "$hfvis" normals "$dir/slope.pgm" --quiet -o "$dir/slices.pfm" 2> "$dir/terr"; then
  head=$(head -c 18 "$dir/slices.pfm" | od -A n -c | tr -d ' \n')
  size=$(wc -c < "$dir/slices.pfm" | tr -d ' ')
  first=$(od -A n -t f4 -j 18 -N 4 "$dir/slices.pfm" | tr -d ' ')
  last=$(od -A n -t f4 -j $((size - 12)) -N 4 "$dir/slices.pfm" | tr -d ' ')
  [ "$head" = 'PF\n24001000\n-1.0\n' ] && [ "$size" = $((18 + 2400 * 1000 * 12)) ] && [ "$first" != 0 ] &&
    [ "$last" = 0 ] && ok "PFM written in slices: the whole image's header and size, bottom row first" ||
    bad "PFM slices: header '$head' size $size first $first last $last $(cat "$dir/terr")"
else bad "PFM slices: $(cat "$dir/terr")"; fi
rm -f "$dir/slices.pfm" "$dir/slope.pgm"
"$hfvis" skyview "$r" --nodata 0 --cell 3 --quiet --threads 0 -o "$dir/thr0.pfm" && "$hfvis" skyview "$r" --nodata 0 --cell 3 \
  --quiet -o "$dir/thr1.pfm" && cmp -s "$dir/thr0.pfm" "$dir/thr1.pfm" && ok "--threads 0 (the online cores) = the default run" \
  || bad "--threads 0"
# a window piece is the same on any number of threads too (windows read PFM: heights from the tool)
"$hfvis" hillshade "$r" --nodata 0 --no-shadows --quiet -o "$dir/rough.pfm"
for t in 1 2; do "$hfvis" skyview "$dir/rough.pfm" --cell 0.05 --max-distance 1.5 --window 10,8,30,25 --threads $t \
  --quiet -o "$dir/win$t.pfm" 2> "$dir/terr"; done
cmp -s "$dir/win1.pfm" "$dir/win2.pfm" && ok "--threads with --window: the piece is the same" || bad "--threads with --window: $(cat "$dir/terr")"
for t in 1 3; do "$hfvis" sky "$dir/rough.pfm" --exact --cell 0.05 --max-distance 1.5 --window 10,8,30,25 --threads $t \
  --quiet -o "$dir/win$t.pfm" 2> "$dir/terr"; done
cmp -s "$dir/win1.pfm" "$dir/win3.pfm" && ok "--threads with --window, exact bands: the piece is the same" || bad "--threads with --window, exact: $(cat "$dir/terr")"
"$hfvis" skyview "$r" --dirs 16 --dir-range 0:8 --threads 2 -o "$fdir/p.hfvs" 2> "$dir/terr"
[ $? -eq 2 ] && grep -q -- '--threads' "$dir/terr" && ok "--threads 2 with --dir-range refused by name" || bad "--threads with --dir-range: $(cat "$dir/terr")"
"$hfvis" openness "$r" --threads 2 -o "$fdir/o.pfm" 2> "$dir/terr"
[ $? -eq 2 ] && grep -q -- '--threads' "$dir/terr" && ok "openness --threads 2 without --radius refused by name" || bad "openness --threads: $(cat "$dir/terr")"
"$hfvis" viewshed "$r" --observer 5,5 --threads 2 -o "$fdir/v.pfm" 2> "$dir/terr"
[ $? -eq 2 ] && grep -q -- '--threads is not used by viewshed' "$dir/terr" && ok "viewshed refuses --threads by name" || bad "viewshed --threads: $(cat "$dir/terr")"
# hillshade's shadows are those of shadow --exact: every cell it darkens is dark, lit cells keep
# the local shading (--no-shadows)
"$hfvis" hillshade "$r" --nodata 0 --cell 3 --sun-azimuth 300 --sun-elevation 12 --quiet -o "$dir/hs.pfm" &&
"$hfvis" shadow "$r" --nodata 0 --cell 3 --sun-azimuth 300 --sun-elevation 12 --exact --quiet -o "$dir/sx.pfm" &&
"$hfvis" hillshade "$r" --nodata 0 --cell 3 --sun-azimuth 300 --sun-elevation 12 --no-shadows --quiet -o "$dir/hn.pfm"
if [ -s "$dir/hs.pfm" ] && [ -s "$dir/sx.pfm" ] && [ -s "$dir/hn.pfm" ]; then
  for f in sx hs hn; do tail -c +$(($(head -3 "$dir/$f.pfm" | wc -c) + 1)) "$dir/$f.pfm" | od -An -v -tf4 -w4 > "$dir/$f.txt"; done
  res=$(paste "$dir/sx.txt" "$dir/hs.txt" "$dir/hn.txt" | awk '$1 == "nan" || $1 == "-nan" { next }
    $1 == 0 { dark++; if ($2 != 0) miss++ } $1 == 1 && $2 != $3 { lit++ } END { printf "%d %d %d", dark, miss, lit }')
  set -- $res
  [ "$1" -gt 0 ] && [ "$2" -eq 0 ] && [ "$3" -eq 0 ] && ok "hillshade shadows = shadow --exact ($1 shadow cells)" || bad "hillshade vs shadow --exact: dark $1, missed $2, lit changed $3"
else bad "hillshade/shadow --exact did not run"; fi

# ---- every command x every flag, from the tables ('hfvis --list-commands', '--list-flags') ----
# A flag the command does not use: exit 2, one line "hfvis: CMD: FLAG is not used by CMD". A flag
# it uses, given the value '@bad' (or none for a switch): never refused as unused or unknown,
# and a refusal of the value is one line naming the flag. Every flag of the table in docs/cli.md.
"$hfvis" --list-flags > "$dir/flags" && "$hfvis" --list-commands > "$dir/commands" &&
  [ -s "$dir/flags" ] && [ -s "$dir/commands" ] && ok "--list-flags, --list-commands" || bad "--list-flags, --list-commands"
awk -F'	' 'NF != 7 || $4 !~ /^(-|int|real|text|choice|list|date|bytes|duration)$/ { bad = 1 }
  END { exit bad }' "$dir/flags" &&
  ok "--list-flags: NAME VALUE COMMANDS TYPE RANGE DEFAULT UNIT" || bad "--list-flags columns"
[ "$(wc -l < "$dir/commands" | tr -d ' ')" = "$("$hfvis" --help | sed -n '/^commands:/,/^$/p' | grep -c '^  [a-z]')" ] &&
  ok "--list-commands: the commands of --help" || bad "--list-commands differs from --help"
walk_bad=0; walk_n=0; help_n=0
walk_fail() { walk_bad=$((walk_bad + 1)); echo "FAIL cli walk: $1"; }
while read -r c; do # one run per pair, no other process: the walk is ~2,000 runs
  "$hfvis" --list-flags "$c" > "$dir/cflags"
  used=" $(cut -f1 "$dir/cflags" | tr '\n' ' ') "
  # --list-flags CMD: exactly the rows of the whole table whose COMMANDS name CMD
  awk -F'	' -v c="$c" 'index("," $3 ",", "," c ",")' "$dir/flags" | cmp -s - "$dir/cflags" ||
    walk_fail "$c: --list-flags $c is not the table's rows naming $c"
  # 'hfvis CMD --help' ends with each option's type, range, default and unit: --list-flags' columns
  "$hfvis" "$c" --help | sed -n '/^values of /,$p' | sed 1d > "$dir/chelp"
  awk -F'	' '{ s = sprintf("  %-18s  %s", $1 ($2 == "-" ? "" : " " $2), $4 == "-" ? "switch" : $4)
    if ($5 != "-") s = s " in " $5; if ($6 != "-") s = s ", default " $6; if ($7 != "-") s = s ", unit " $7
    print s }' "$dir/cflags" | cmp -s - "$dir/chelp" && help_n=$((help_n + $(wc -l < "$dir/chelp"))) ||
    walk_fail "$c --help: its options' values differ from --list-flags $c"
  while IFS='	' read -r f v cmds _columns; do
    case ",$cmds," in *",$c,"*) ;; *) case "$used" in *" $f "*) continue ;; esac ;; esac # another meaning's row
    walk_n=$((walk_n + 1))
    if [ "$v" = - ]; then err=$("$hfvis" "$c" "$f" 2>&1 > /dev/null); rc=$?
    else err=$("$hfvis" "$c" "$f" @bad 2>&1 > /dev/null); rc=$?; fi
    case "$err" in *"
"*) n=2 ;; "") n=0 ;; *) n=1 ;; esac
    case "$used" in
    *" $f "*)
      case "$err" in *"is not used by"* | *"unknown option"*) walk_fail "$c uses $f but refused it: $err" ;; esac
      if [ "$rc" -ne 0 ] && [ "$n" -ne 1 ]; then walk_fail "$c $f: exit $rc with $n lines"; fi
      case "$err" in *expected*) case "$err" in *"$f"*) ;; *) walk_fail "$c $f @bad: not named in: $err" ;; esac ;; esac ;;
    *)
      case "$rc $n $err" in "2 1 hfvis: $c: $f is not used by $c"*) ;; *) walk_fail "$c does not use $f: exit $rc: $err" ;; esac ;;
    esac
  done < "$dir/flags"
done < "$dir/commands"
[ "$walk_bad" -eq 0 ] && ok "walk: $walk_n command x flag pairs" || bad "walk: $walk_bad of $walk_n pairs"
[ "$walk_bad" -eq 0 ] && [ "$help_n" -gt 0 ] && ok "every command's --help: the type, range, default and unit of its $help_n options as in --list-flags" ||
  bad "--help values: $help_n lines checked"
# No mutable state at file scope: the binary's writable objects (.data, .bss) are the C runtime's
# and the signal handler's temporary-file names (cli_tmp_name, cli_tmp_armed, and common.h's
# ex_atomic_on_temp hook that reports the raster writers' to it) with the hold of those signals
# while a raster's files are published (zio.h's ex_atomic_hold hook, cli_hold_mask and
# cli_hold_depth). Needs an nm that prints sections.
if nm -f sysv "$hfvis" > "$dir/nm" 2> /dev/null && grep -q '|\.bss' "$dir/nm"; then
  extra=$(awk -F'|' '$4 ~ /OBJECT/ && $7 ~ /^\.(data|bss)$/ { gsub(/ /, "", $1); print $1 }' "$dir/nm" |
    grep -v -e '@' -e '^__' -e '^completed\.' -e '^cli_tmp_name$' -e '^cli_tmp_armed$' -e '^ex_atomic_on_temp$' \
      -e '^ex_atomic_hold$' -e '^cli_hold_mask$' -e '^cli_hold_depth$' | tr '\n' ' ')
  [ -z "$extra" ] && ok "no mutable objects but the signal handler's temporary-file names (nm)" ||
    bad "mutable objects at file or function scope: $extra"
else
  echo "SKIP cli mutable objects: no 'nm -f sysv' with sections"
fi
# every refusal of a bad number names the flag and its range
"$hfvis" skyview "$h" --dirs 0 -o "$fdir/x.pfm" 2> "$dir/werr"
grep -q -- '--dirs.*1\.\.65536' "$dir/werr" && ok "--dirs 0: flag and range" || bad "--dirs 0: $(cat "$dir/werr")"
here=$(cd "$(dirname "$0")" && pwd)
if [ -f "$here/../docs/cli.md" ]; then
  missing=$(cut -f1 "$dir/flags" | while read -r f; do grep -qF -- "\`$f" "$here/../docs/cli.md" || printf '%s ' "$f"; done)
  [ -z "$missing" ] && ok "docs/cli.md names every flag" || bad "docs/cli.md lacks: $missing"
  missing=$(while read -r c; do grep -qF -- "\`$c\`" "$here/../docs/cli.md" || printf '%s ' "$c"; done < "$dir/commands")
  [ -z "$missing" ] && ok "docs/cli.md names every command" || bad "docs/cli.md lacks commands: $missing"
else
  echo "SKIP cli docs/cli.md: not beside the script"
fi

# ---- solar (docs/solar.md) ----------------------------------------------------------------
# utm.asc + utm.prj: 8 x 6 cells of 10 m in UTM 33N whose centre lies at E 500040, N 5000030:
# latitude 45.1538 (the meridian arc to 45 deg, 4984944 m, times 0.9996 is N 4982950; 17080 m more
# of northing is 0.1538 deg), longitude 15.0005, by the inverse Transverse Mercator.
awk 'BEGIN { print "ncols 8"; print "nrows 6"; print "xllcorner 500000"; print "yllcorner 5000000"
  print "cellsize 10"; for (y = 0; y < 6; y++) { s = ""; for (x = 0; x < 8; x++) s = s " " (100 + x); print s } }' > "$dir/utm.asc"
printf 'PROJCS["WGS 84 / UTM zone 33N",GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],PARAMETER["latitude_of_origin",0],PARAMETER["central_meridian",15],PARAMETER["scale_factor",0.9996],PARAMETER["false_easting",500000],PARAMETER["false_northing",0],UNIT["metre",1]]\n' > "$dir/utm.prj"
expect_ok "solar: a day on flat ground" "$dir/sol.pfm" solar "$dir/flat.pgm" --latitude 46 --longitude 15 --day 2026-06-21 --utc-offset 1 --dirs 8 -o "$dir/sol.pfm"
expect_ok "solar: instant, parts and sun hours" "$dir/solh.pfm" solar "$dir/hill.pgm" --latitude -35 --longitude 150 --day 2026-01-10 --time 12:30 --utc-offset 10 --dirs 8 --beam "$dir/solb.pfm" --diffuse "$dir/sold.pfm" --reflected "$dir/solr.pfm" --sun-hours "$dir/solh.pfm" -o "$dir/solg.pfm"
[ -s "$dir/solb.pfm" ] && [ -s "$dir/sold.pfm" ] && [ -s "$dir/solr.pfm" ] && ok "solar: the four extra outputs written" || bad "solar: an extra output missing"
expect_ok "solar: polar night gives 0" "$dir/night.pfm" solar "$dir/flat.pgm" --latitude 80 --longitude 15 --day 2026-12-21 --dirs 8 -o "$dir/night.pfm"
expect_bytes "solar: polar night is 0 Wh/m^2" "$dir/night.pfm" 4 "00 00 00 00"
expect_ok "solar: r.sun's solar time, monthly Linke, month bands" "$dir/solm.pfm" solar "$dir/hill.pgm" --latitude 46 --longitude 15 --start 2026-01-30 --end 2026-02-02 --solar-time --linke-monthly 2,2,3,3,4,4,4,4,3,3,2,2 --bands month --step 1h --dirs 8 -o "$dir/solm.pfm"
[ "$(head -c 20 "$dir/solm.pfm" | sed -n 2p)" = "24 40" ] && ok "solar: 2 month bands stacked (24 x 40)" || bad "solar: month bands: $(head -c 20 "$dir/solm.pfm" | sed -n 2p)"
"$hfvis" solar "$dir/utm.asc" --day 2026-06-21 --dirs 8 --progress -o "$dir/utm.tif" > "$dir/stdout" 2> "$dir/stderr"
grep -q '^hfvis solar: site 45\.153[78][0-9]*, 15\.0005[0-9]* ' "$dir/stderr" && "$hfvis" info "$dir/utm.tif" | grep -q 'crs projected' \
  && ok "solar: UTM 33N asc + .prj: the site by the inverse projection, GeoTIFF with the CRS" \
  || bad "solar: UTM site or CRS: $(grep site "$dir/stderr") $("$hfvis" info "$dir/utm.tif" | grep crs)"
# a CRS that names Transverse Mercator without its parameters: refused, not taken as k0 = 1 at
# the Greenwich meridian
cp "$dir/utm.asc" "$dir/tmnp.asc"
printf 'PROJCS["NZGD2000 / New Zealand Transverse Mercator 2000",PROJECTION["Transverse_Mercator"]]\n' > "$dir/tmnp.prj"
expect_fail "solar: Transverse Mercator without parameters" 1 solar "$dir/tmnp.asc" --day 2026-06-21 --dirs 8 -o "$fdir/x.pfm"
# tall.asc: 2 x 40 cells of 10 km in UTM 33N, 45.0 to 48.6 deg north: each cell its own site (by
# the inverse projection), so on December 21 the south row (the PFM's first) gets more than the
# north row (its last); one site for the whole grid would give the two the same.
awk 'BEGIN { print "ncols 2"; print "nrows 40"; print "xllcorner 490000"; print "yllcorner 5000000"
  print "cellsize 10000"; for (y = 0; y < 40; y++) print " 0 0" }' > "$dir/tall.asc"
cp "$dir/utm.prj" "$dir/tall.prj"
expect_ok "solar: per-cell sites over 3.6 deg of latitude" "$dir/tall.pfm" solar "$dir/tall.asc" --day 2026-12-21 --dirs 8 -o "$dir/tall.pfm"
if [ "$little_endian" = 1 ]; then
  south=$(od -An -tf4 -j $(($(wc -c < "$dir/tall.pfm") - 320)) -N 4 "$dir/tall.pfm" | tr -d ' ')
  north=$(tail -c 4 "$dir/tall.pfm" | od -An -tf4 | tr -d ' ')
  awk -v s="$south" -v n="$north" 'BEGIN { exit !(s > 1.15 * n && n > 0) }' \
    && ok "solar: the south row gets more than the north row ($south, $north Wh/m^2)" \
    || bad "solar: per-cell sites: south $south, north $north"
fi
expect_ok "solar --threads 3 (the horizon map by directions)" "$dir/solt3.pfm" solar "$dir/hill.pgm" --latitude 46 --longitude 15 --start 2026-03-01 --end 2026-03-05 --threads 3 -o "$dir/solt3.pfm"
expect_ok "solar --threads 1" "$dir/solt1.pfm" solar "$dir/hill.pgm" --latitude 46 --longitude 15 --start 2026-03-01 --end 2026-03-05 -o "$dir/solt1.pfm"
cmp -s "$dir/solt1.pfm" "$dir/solt3.pfm" && ok "solar --threads 3 equals one thread bit for bit" || bad "solar --threads 3 differs from one thread"
expect_ok "solar --threads 2, 30 days (the sector sums by rows)" "$dir/sols2.pfm" solar "$dir/hill.pgm" --latitude 46 --longitude 15 --start 2026-03-01 --end 2026-03-30 --dirs 8 --threads 2 -o "$dir/sols2.pfm"
expect_ok "solar --threads 1, 30 days" "$dir/sols1.pfm" solar "$dir/hill.pgm" --latitude 46 --longitude 15 --start 2026-03-01 --end 2026-03-30 --dirs 8 --threads 1 -o "$dir/sols1.pfm"
cmp -s "$dir/sols1.pfm" "$dir/sols2.pfm" && ok "solar --threads 2: the integration by rows equals one thread bit for bit (30 days)" || bad "solar --threads 2 (30 days) differs from one thread"
expect_ok "solar --threads 2, per-cell sites" "$dir/tall2.pfm" solar "$dir/tall.asc" --day 2026-12-21 --dirs 8 --threads 2 -o "$dir/tall2.pfm"
expect_ok "solar --threads 1, per-cell sites" "$dir/tall1.pfm" solar "$dir/tall.asc" --day 2026-12-21 --dirs 8 --threads 1 -o "$dir/tall1.pfm"
cmp -s "$dir/tall1.pfm" "$dir/tall2.pfm" && ok "solar --threads 2 with per-cell sites equals one thread bit for bit" || bad "solar --threads 2 with per-cell sites differs from one thread"
for hz in near-far lattice; do
  expect_ok "solar --horizons $hz --threads 2" "$dir/solz2.pfm" solar "$dir/hill.pgm" --latitude 46 --longitude 15 --day 2026-06-21 --horizons $hz --threads 2 -o "$dir/solz2.pfm"
  expect_ok "solar --horizons $hz --threads 1" "$dir/solz1.pfm" solar "$dir/hill.pgm" --latitude 46 --longitude 15 --day 2026-06-21 --horizons $hz --threads 1 -o "$dir/solz1.pfm"
  cmp -s "$dir/solz1.pfm" "$dir/solz2.pfm" && ok "solar --horizons $hz: the threaded map (hfvis_solar_map_options) equals one thread bit for bit" || bad "solar --horizons $hz: --threads 2 differs from one thread"
done
"$hfvis" solar "$dir/hill.pgm" --latitude 46 --longitude 15 --day 2026-06-21 --horizons exact --threads 1 -o "$dir/solze.pfm" 2>/dev/null
cmp -s "$dir/solz1.pfm" "$dir/solze.pfm" && bad "solar --horizons lattice: equals exact bit for bit (mode not applied)" || ok "solar --horizons lattice differs from exact"
"$hfvis" solar --help 2>&1 | grep -q -- '--horizons exact|near-far|lattice' && ok "solar --help lists --horizons" || bad "solar --help: no --horizons"
expect_fail "solar: bad --horizons" 2 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --day 2026-06-21 --horizons fast -o "$fdir/x.pfm"
# --normals horn (Horn's 3x3 stencil): differs from central on a rough field, is central on a plane
# (Horn's gradient is exact there; integer heights: bit for bit)
awk 'BEGIN { print "P2"; print "16 12"; print "255"; r = 7
  for (y = 0; y < 12; y++) { s = ""; for (x = 0; x < 16; x++) { r = (r * 1103515245 + 12345) % 2147483648; s = s " " int(r / 2147483648 * 200) } print s } }' > "$dir/rough.pgm"
awk 'BEGIN { print "P2"; print "16 12"; print "255"
  for (y = 0; y < 12; y++) { s = ""; for (x = 0; x < 16; x++) s = s " " (20 + 9 * x + 4 * y); print s } }' > "$dir/ramp.pgm"
for f in rough ramp; do
  for n in central horn; do
    expect_ok "solar --normals $n on $f" "$dir/n_${f}_$n.pfm" solar "$dir/$f.pgm" --latitude 46 --longitude 15 --day 2026-03-21 --dirs 8 --normals $n -o "$dir/n_${f}_$n.pfm"
  done
done
cmp -s "$dir/n_rough_central.pfm" "$dir/n_rough_horn.pfm" && bad "solar --normals horn equals central on a rough field" || ok "solar --normals horn differs from central on a rough field"
cmp -s "$dir/n_ramp_central.pfm" "$dir/n_ramp_horn.pfm" && ok "solar --normals horn equals central on a plane" || bad "solar --normals horn differs from central on a plane"
expect_fail "solar: bad --normals" 2 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --day 2026-06-21 --normals sobel -o "$fdir/x.pfm"
expect_fail "solar: no latitude (no CRS)" 1 solar "$dir/flat.pgm" --day 2026-06-21 -o "$fdir/x.pfm"
expect_fail "solar: a date that does not exist" 2 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --day 2026-02-29 -o "$fdir/x.pfm"
expect_fail "solar: Linke outside (0, 10]" 2 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --day 2026-06-21 --linke 0 -o "$fdir/x.pfm"
expect_fail "solar: albedo outside [0, 1]" 2 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --day 2026-06-21 --albedo 1.2 -o "$fdir/x.pfm"
# the memory estimate counts the sample-major copy of the map only where a period's sums read it
expect_fail "solar, a day, over --max-memory 1K" 1 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --day 2026-06-21 --max-memory 1K -o "$fdir/x.pfm"; m1=$(mib)
expect_fail "solar, 30 days, over --max-memory 1K" 1 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --start 2026-06-01 --end 2026-06-30 --max-memory 1K -o "$fdir/x.pfm"; m3=$(mib)
awk -v a="$m1" -v b="$m3" 'BEGIN { exit !(a > 0 && b > 1.4 * a) }' &&
  ok "estimate: solar 30 days $m3 MiB > a day $m1 MiB (the sample-major copy)" || bad "estimate: solar 30 days '$m3' MiB not above a day '$m1' MiB"
# band stacks: each output holds 4 bytes per cell and band, the library 32 bytes of sums per
# cell and band: a year of day bands into three outputs on 100 x 100 cells needs at least
# 10^4 x 365 x (32 + 3 x 4) bytes = 153 MiB
expect_fail "solar, a year of day bands, 3 outputs, over --max-memory 1K" 1 solar "$dir/big.pgm" --latitude 46 --longitude 15 --start 2026-01-01 --end 2026-12-31 --bands day --max-memory 1K -o "$fdir/x.tif" --beam "$fdir/y.tif" --diffuse "$fdir/z.tif"; m3=$(mib)
awk -v b="$m3" 'BEGIN { exit !(b >= 153 && b < 250) }' &&
  ok "estimate: a year of day bands into 3 outputs $m3 MiB (>= 153)" || bad "estimate: a year of day bands into 3 outputs '$m3' MiB, want >= 153"
# and the automatic thread count follows it: 90 day bands into 3 outputs, about 42 MiB, keep
# one thread under --max-memory 80M (a thread's scratch counts as a whole run's)
"$hfvis" solar "$dir/big.pgm" --cell 1 --latitude 46 --longitude 15 --start 2026-01-01 --end 2026-03-31 --bands day --dirs 8 --max-memory 0 --progress -o "$dir/sbt.tif" --beam "$dir/sbt2.tif" --diffuse "$dir/sbt3.tif" > /dev/null 2> "$dir/stderr"
if grep -q '^solar: estimate .*, 1 thread$' "$dir/stderr"; then ok "solar threads under --max-memory: skipped (one core)"
else
  "$hfvis" solar "$dir/big.pgm" --cell 1 --latitude 46 --longitude 15 --start 2026-01-01 --end 2026-03-31 --bands day --dirs 8 --max-memory 80M --progress -o "$dir/sbt.tif" --beam "$dir/sbt2.tif" --diffuse "$dir/sbt3.tif" > /dev/null 2> "$dir/stderr"
  grep -q '^solar: estimate 4[0-9.]* MiB, .*, 1 thread$' "$dir/stderr" && ok "solar: the band stack keeps one thread under --max-memory 80M" ||
    bad "solar threads under --max-memory 80M: $(grep estimate "$dir/stderr")"
fi
expect_fail "solar: latitude without longitude" 2 solar "$dir/flat.pgm" --latitude 46 --day 2026-06-21 -o "$fdir/x.pfm"
expect_fail "solar: --time with a range" 2 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --start 2026-06-01 --end 2026-06-02 --time 12:00 -o "$fdir/x.pfm"
expect_fail "solar: --solar-time with --utc-offset" 2 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --day 2026-06-21 --solar-time --utc-offset 1 -o "$fdir/x.pfm"
expect_fail "solar: no date" 2 solar "$dir/flat.pgm" --latitude 46 --longitude 15 -o "$fdir/x.pfm"
expect_fail "solar: --window without --max-distance" 2 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --day 2026-06-21 --window 0,0,2,2 -o "$fdir/x.pfm"
# solar --window: swin.asc, 37 x 29 cells of 400 m in UTM 33N (0.1 deg of latitude: several
# blocks of per-cell suns at the default tolerance), cut into 5 uneven windows (one a single row,
# the others touching the raster's edges); 'mosaic' of the pieces of each output equals the
# whole run with the same --max-distance byte for byte: per-cell sites (30 days: the sector
# sums, --threads 2 against 1), one site (a day: the day path), an instant.
awk 'BEGIN { srand(5); print "ncols 37"; print "nrows 29"; print "xllcorner 480000"; print "yllcorner 5000000"
  print "cellsize 400"; for (y = 0; y < 29; y++) { s = ""
    for (x = 0; x < 37; x++) s = s " " int(1000 + 400 * sin(x / 5) * cos(y / 4) + 150 * sin((x + 2 * y) / 3) + 30 * rand())
    print s } }' > "$dir/swin.asc"
cp "$dir/utm.prj" "$dir/swin.prj"
# solar_tiles NAME ARGS...: the whole run (global and beam GeoTIFFs), the 5 windows' pieces, the
# two mosaics, compared byte for byte
solar_tiles() {
  sname=$1; shift
  expect_ok "solar tiles $sname: whole run" "$dir/stw_g.tif" solar "$dir/swin.asc" "$@" --max-distance 2000 --beam "$dir/stw_b.tif" -o "$dir/stw_g.tif"
  rm -f "$dir"/stp_*
  for win in 0,0,20,13 20,0,17,13 0,13,37,1 0,14,11,15 11,14,26,15; do
    wn=$(echo "$win" | tr , _)
    expect_ok "solar tiles $sname: window $win" "$dir/stp_g_$wn.tif" solar "$dir/swin.asc" "$@" --max-distance 2000 --window "$win" --beam "$dir/stp_b_$wn.tif" -o "$dir/stp_g_$wn.tif"
  done
  expect_ok "solar tiles $sname: mosaic of the global pieces" "$dir/stm_g.tif" mosaic "$dir"/stp_g_*.tif -o "$dir/stm_g.tif"
  expect_ok "solar tiles $sname: mosaic of the beam pieces" "$dir/stm_b.tif" mosaic "$dir"/stp_b_*.tif -o "$dir/stm_b.tif"
  cmp -s "$dir/stw_g.tif" "$dir/stm_g.tif" && cmp -s "$dir/stw_b.tif" "$dir/stm_b.tif" &&
    ok "solar tiles $sname: the mosaics equal the whole run byte for byte (global, beam)" ||
    bad "solar tiles $sname: a mosaic differs from the whole run"
}
solar_tiles "per-cell sites, 30 days, --threads 2" --start 2026-03-01 --end 2026-03-30 --dirs 16 --threads 2
cp "$dir/stw_g.tif" "$dir/stw_g_t2.tif"
expect_ok "solar tiles: per-cell sites, 30 days, --threads 1 whole run" "$dir/stw_g.tif" solar "$dir/swin.asc" --start 2026-03-01 --end 2026-03-30 --dirs 16 --threads 1 --max-distance 2000 -o "$dir/stw_g.tif"
cmp -s "$dir/stw_g.tif" "$dir/stw_g_t2.tif" && ok "solar tiles: --threads 2 equals --threads 1 (per-cell sites, 30 days)" || bad "solar tiles: --threads 2 differs from --threads 1"
# --bands day and month: each GeoTIFF band described by its date or month (GDAL_METADATA), the
# unit Wh/m^2, in the whole run and in the mosaic of its pieces alike
solar_tiles "day bands across February's end" --start 2026-02-27 --end 2026-03-02 --bands day --dirs 8
grep -a -q '<Item name="DESCRIPTION" sample="3" role="description">2026-03-02</Item>' "$dir/stm_g.tif" &&
  grep -a -q '<Item name="DESCRIPTION" sample="1" role="description">2026-02-28</Item>' "$dir/stm_g.tif" &&
  grep -a -q 'Wh/m^2' "$dir/stm_g.tif" &&
  ok "solar --bands day: bands described by their dates (2026-02-27 .. 2026-03-02), unit Wh/m^2" ||
  bad "solar --bands day: band descriptions: $(grep -a -o '<Item name="DESCRIPTION"[^<]*</Item>' "$dir/stm_g.tif" | head -5)"
solar_tiles "month bands across the year's end" --start 2026-11-20 --end 2027-01-03 --bands month --dirs 8
grep -a -q 'role="description">2026-11</Item>' "$dir/stw_g.tif" && grep -a -q 'role="description">2027-01</Item>' "$dir/stw_g.tif" &&
  ok "solar --bands month: bands described by their months" ||
  bad "solar --bands month: $(grep -a -o '<Item name="DESCRIPTION"[^<]*</Item>' "$dir/stw_g.tif" | head -5)"
expect_ok "normals -> tif" "$dir/nrm.tif" normals "$dir/swin.asc" -o "$dir/nrm.tif"
grep -a -q 'role="description">x (east)</Item>' "$dir/nrm.tif" && grep -a -q 'role="description">z (up)</Item>' "$dir/nrm.tif" &&
  ok "normals GeoTIFF: bands described x (east), y (south), z (up)" || bad "normals GeoTIFF: no band descriptions"
solar_tiles "per-cell sites, a day" --day 2026-06-21 --threads 1
solar_tiles "--latitude/--longitude, a day, --threads 2" --day 2026-06-21 --latitude 46 --longitude 15 --threads 2
# --height-range LO,HI: the pressure nodes' span given, no pass over IN; the pieces still join
# into the whole run with the same range, a height outside it is refused, and a piece made
# without it does not join those made with it
solar_tiles "--height-range, a day" --day 2026-06-21 --latitude 46 --longitude 15 --height-range 0,2000 --threads 2
# heights compared as the floats they are: 1000.1 read from text is the float 1000.0999756, below
# the double 1000.1, and is still inside --height-range 1000.1,2000.7
awk 'BEGIN { print "ncols 6"; print "nrows 5"; print "xllcorner 480000"; print "yllcorner 5000000"; print "cellsize 400"
  for (y = 0; y < 5; y++) { s = ""; for (x = 0; x < 6; x++) s = s " " ((x + y) % 3 ? "1500.3" : (x ? "2000.7" : "1000.1")); print s } }' > "$dir/sdec.asc"
expect_ok "solar --height-range with the decimal extremes of the heights" "$dir/sdec.tif" solar "$dir/sdec.asc" --day 2026-06-21 --latitude 46 --longitude 15 --max-distance 2000 --window 0,0,3,3 --height-range 1000.1,2000.7 -o "$dir/sdec.tif"
expect_fail "solar --height-range below the heights read" 1 solar "$dir/swin.asc" --day 2026-06-21 --latitude 46 --longitude 15 --max-distance 2000 --window 0,0,20,13 --height-range 0,1200 -o "$fdir/x.tif"
expect_fail "solar --height-range with one value" 2 solar "$dir/swin.asc" --day 2026-06-21 --latitude 46 --longitude 15 --height-range 5 -o "$fdir/x.tif"
expect_fail "solar --height-range LO > HI" 2 solar "$dir/swin.asc" --day 2026-06-21 --latitude 46 --longitude 15 --height-range 9,3 -o "$fdir/x.tif"
expect_fail "solar --height-range not finite" 2 solar "$dir/swin.asc" --day 2026-06-21 --latitude 46 --longitude 15 --height-range 0,inf -o "$fdir/x.tif"
expect_ok "solar tiles: a piece without --height-range" "$dir/stp_g_0_0_20_13.tif" solar "$dir/swin.asc" --day 2026-06-21 --latitude 46 --longitude 15 --max-distance 2000 --window 0,0,20,13 -o "$dir/stp_g_0_0_20_13.tif"
expect_fail "solar tiles: mosaic refuses a piece made without --height-range among pieces with it" 1 mosaic "$dir"/stp_g_*.tif -o "$fdir/x.tif"
solar_tiles "per-cell sites, an instant" --day 2026-06-21 --time 09:30 --threads 1
"$hfvis" mosaic "$dir"/stp_g_0_0_20_13.tif "$dir"/stp_b_20_0_17_13.tif "$dir"/stp_b_0_13_37_1.tif "$dir"/stp_b_0_14_11_15.tif "$dir"/stp_b_11_14_26_15.tif -o "$fdir/x.tif" > /dev/null 2> "$dir/stderr" &&
  bad "solar tiles: mosaic joined a global piece with beam pieces" || { grep -q 'solar-output' "$dir/stderr" &&
  ok "solar tiles: mosaic refuses a global piece among beam pieces: $(cat "$dir/stderr")" || bad "solar tiles: mixed outputs: $(cat "$dir/stderr")"; }
# per-cell maps of the raster's size (a 16-bit PGM Linke map, values (0, 1], and a PFM albedo
# map): each window reads its cells of them; pieces made with another map do not join
expect_ok "solar tiles: a Linke map (PGM)" "$dir/slk.pgm" skyview "$dir/swin.asc" --dirs 8 -o "$dir/slk.pgm"
expect_ok "solar tiles: an albedo map (PFM)" "$dir/salb.pfm" skyview "$dir/swin.asc" --dirs 8 -o "$dir/salb.pfm"
expect_ok "solar tiles: another albedo map (PFM)" "$dir/salb2.pfm" skyview "$dir/swin.asc" --dirs 16 -o "$dir/salb2.pfm"
solar_tiles "per-cell sites, a day, --linke-map and --albedo-map" --day 2026-06-21 --threads 2 --linke-map "$dir/slk.pgm" --albedo-map "$dir/salb.pfm"
expect_ok "solar tiles: a piece with another albedo map" "$dir/stp_g_0_0_20_13.tif" solar "$dir/swin.asc" --day 2026-06-21 --threads 2 --linke-map "$dir/slk.pgm" --albedo-map "$dir/salb2.pfm" --max-distance 2000 --window 0,0,20,13 -o "$dir/stp_g_0_0_20_13.tif"
expect_fail "solar tiles: mosaic refuses a piece made with another albedo map" 1 mosaic "$dir"/stp_g_*.tif -o "$fdir/x.tif"
expect_fail "solar --window with a Linke map of another size" 1 solar "$dir/swin.asc" --day 2026-06-21 --max-distance 2000 --window 0,0,5,5 --linke-map "$dir/flat.pgm" -o "$fdir/x.tif"
# the maps are read as IN is: GeoTIFF, ASC and EHdr (a window reads its cells of them), the same
# floats as a PFM of them give the same outputs byte for byte; a map of several bands is refused
expect_ok "solar maps: a Linke map (GeoTIFF)" "$dir/slk8.tif" skyview "$dir/swin.asc" --dirs 8 -o "$dir/slk8.tif"
expect_ok "solar maps: the same Linke map (PFM)" "$dir/slk8.pfm" skyview "$dir/swin.asc" --dirs 8 -o "$dir/slk8.pfm"
expect_ok "solar maps: an albedo map (ASC)" "$dir/salb16.asc" skyview "$dir/swin.asc" --dirs 16 -o "$dir/salb16.asc"
expect_ok "solar maps: an albedo map (EHdr)" "$dir/salb16.flt" skyview "$dir/swin.asc" --dirs 16 -o "$dir/salb16.flt"
expect_ok "solar with PFM maps" "$dir/smp.tif" solar "$dir/swin.asc" --day 2026-06-21 --dirs 8 --linke-map "$dir/slk8.pfm" --albedo-map "$dir/salb2.pfm" -o "$dir/smp.tif"
expect_ok "solar with a GeoTIFF Linke map and an ASC albedo map" "$dir/smr.tif" solar "$dir/swin.asc" --day 2026-06-21 --dirs 8 --linke-map "$dir/slk8.tif" --albedo-map "$dir/salb16.asc" -o "$dir/smr.tif"
cmp -s "$dir/smp.tif" "$dir/smr.tif" && ok "solar: GeoTIFF and ASC maps give the PFM maps' output byte for byte" || bad "solar: raster maps differ from the PFM maps"
expect_ok "solar with an EHdr albedo map" "$dir/sme.tif" solar "$dir/swin.asc" --day 2026-06-21 --dirs 8 --linke-map "$dir/slk8.tif" --albedo-map "$dir/salb16.flt" -o "$dir/sme.tif"
cmp -s "$dir/smp.tif" "$dir/sme.tif" && ok "solar: an EHdr map gives the PFM map's output byte for byte" || bad "solar: the EHdr map differs"
solar_tiles "a day, a GeoTIFF Linke map and an ASC albedo map" --day 2026-06-21 --threads 2 --linke-map "$dir/slk8.tif" --albedo-map "$dir/salb16.asc"
expect_ok "solar maps: a map of 3 bands" "$dir/slk3.tif" light "$dir/swin.asc" --env "$dir/env3.pfm" --dirs 4 -o "$dir/slk3.tif"
expect_fail "solar: a Linke map of 3 bands" 1 solar "$dir/swin.asc" --day 2026-06-21 --dirs 8 --linke-map "$dir/slk3.tif" -o "$fdir/x.tif"
grep -q '3 bands or channels' "$dir/stderr" && ok "solar: a map of several bands is refused as such" || bad "solar: 3-band map: $(cat "$dir/stderr")"
expect_fail "solar --window with a GeoTIFF Linke map of another size" 1 solar "$dir/swin.asc" --day 2026-06-21 --max-distance 2000 --window 0,0,5,5 --linke-map "$dir/aux.tif" -o "$fdir/x.tif"
printf 'not an image\n' > "$dir/smap.png"
expect_fail "solar: a map that is no raster names the formats" 1 solar "$dir/swin.asc" --day 2026-06-21 --dirs 8 --albedo-map "$dir/smap.png" -o "$fdir/x.tif"
grep -q 'GeoTIFF' "$dir/stderr" && ok "solar: the refusal of a map names the formats read" || bad "solar: map refusal: $(cat "$dir/stderr")"
expect_fail "solar: bad --step" 2 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --day 2026-06-21 --step 25h -o "$fdir/x.pfm"
expect_fail "solar: bad --linke-monthly" 2 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --day 2026-06-21 --linke-monthly 3,3 -o "$fdir/x.pfm"
# --step takes its unit: a bare number (minutes? r.sun's hours?) is refused; --list-flags says so
sol="solar --latitude 46 --longitude 15 --day 2026-06-21 --dirs 8"
expect_fail "solar: --step 0.5 without a unit" 2 $sol "$dir/flat.pgm" --step 0.5 -o "$fdir/x.pfm"
grep -q "no unit" "$dir/stderr" && ok "solar: a bare --step is refused for its missing unit" || bad "solar --step 0.5: $(cat "$dir/stderr")"
expect_fail "solar: --step 24 without a unit" 2 $sol "$dir/flat.pgm" --step 24 -o "$fdir/x.pfm"
expect_ok "solar --step 0.5h" "$dir/sst1.pfm" $sol "$dir/flat.pgm" --step 0.5h -o "$dir/sst1.pfm"
expect_ok "solar --step 30m" "$dir/sst2.pfm" $sol "$dir/flat.pgm" --step 30m -o "$dir/sst2.pfm"
cmp -s "$dir/sst1.pfm" "$dir/sst2.pfm" && ok "solar: --step 0.5h = --step 30m" || bad "solar: --step 0.5h differs from 30m"
"$hfvis" --list-flags solar | grep -q "^--step	S	solar	duration	(0,24]	15m	hours (m or h required)$" &&
  ok "--list-flags: --step's unit is required" || bad "--list-flags --step: $("$hfvis" --list-flags solar | grep '^--step')"
# dates: --start needs --end, --day takes none, a four-digit year within SPA's -2000..6000
sdate="solar --latitude 46 --longitude 15 --dirs 4"
expect_fail "solar: --start without --end" 2 $sdate "$dir/flat.pgm" --start 2026-06-01 -o "$fdir/x.pfm"
expect_fail "solar: --day with --end" 2 $sdate "$dir/flat.pgm" --day 2026-06-01 --end 2026-06-03 -o "$fdir/x.pfm"
expect_fail "solar: --day with --start" 2 $sdate "$dir/flat.pgm" --day 2026-06-01 --start 2026-06-01 --end 2026-06-03 -o "$fdir/x.pfm"
expect_fail "solar: --end alone" 2 $sdate "$dir/flat.pgm" --end 2026-06-03 -o "$fdir/x.pfm"
expect_fail "solar: a two-digit year" 2 $sdate "$dir/flat.pgm" --day 26-06-21 -o "$fdir/x.pfm"
expect_fail "solar: a one-digit month" 2 $sdate "$dir/flat.pgm" --day 2026-6-21 -o "$fdir/x.pfm"
expect_fail "solar: a year past SPA's 6000" 2 $sdate "$dir/flat.pgm" --day 9999-06-21 -o "$fdir/x.pfm"
grep -q -- "-2000 to 6000" "$dir/stderr" && ok "solar: the refusal of the year 9999 names SPA's years" || bad "solar --day 9999: $(cat "$dir/stderr")"
expect_fail "solar: a year before SPA's -2000" 2 $sdate "$dir/flat.pgm" --day -2001-06-21 -o "$fdir/x.pfm"
expect_ok "solar: the year -500" "$dir/sneg.pfm" $sdate "$dir/flat.pgm" --day -0500-06-21 -o "$dir/sneg.pfm"
# the days of a range counted in the library's calendar (Julian leap years through 1582): 1500 is
# a leap year there, so 1500-02-28 .. 1500-03-01 is 3 days (3 day bands, February and March),
# 1700 is not (2 days); a range across the reform's missing days is refused
expect_ok "solar: 1500-02-28 to 1500-03-01 by day" "$dir/sjul.pfm" $sdate "$dir/flat.pgm" --start 1500-02-28 --end 1500-03-01 --bands day -o "$dir/sjul.pfm"
expect_line2 "solar: 1500-02-28 to 1500-03-01 is 3 days (Julian leap year)" "$dir/sjul.pfm" "8 18"
expect_ok "solar: 1500-02-28 to 1500-03-01 by month" "$dir/sjulm.pfm" $sdate "$dir/flat.pgm" --start 1500-02-28 --end 1500-03-01 --bands month -o "$dir/sjulm.pfm"
expect_line2 "solar: 1500-02-28 to 1500-03-01 reaches March" "$dir/sjulm.pfm" "8 12"
expect_ok "solar: 1700-02-28 to 1700-03-01 by day" "$dir/sgreg.pfm" $sdate "$dir/flat.pgm" --start 1700-02-28 --end 1700-03-01 --bands day -o "$dir/sgreg.pfm"
expect_line2 "solar: 1700-02-28 to 1700-03-01 is 2 days (Gregorian)" "$dir/sgreg.pfm" "8 12"
expect_ok "solar: 1582-12-30 to 1583-01-02 by day" "$dir/sjg.pfm" $sdate "$dir/flat.pgm" --start 1582-12-30 --end 1583-01-02 --bands day -o "$dir/sjg.pfm"
expect_line2 "solar: 1582-12-30 to 1583-01-02 is 4 days" "$dir/sjg.pfm" "8 24"
expect_fail "solar: a range across the Gregorian reform" 2 $sdate "$dir/flat.pgm" --start 1582-10-01 --end 1582-10-20 -o "$fdir/x.pfm"
expect_fail "solar: a day the reform skipped" 2 $sdate "$dir/flat.pgm" --day 1582-10-10 -o "$fdir/x.pfm"
# one source of the Linke factor and of the albedo
expect_fail "solar: --linke with --linke-monthly" 2 $sol "$dir/flat.pgm" --linke 3 --linke-monthly 2,2,3,3,4,4,4,4,3,3,2,2 -o "$fdir/x.pfm"
expect_fail "solar: --linke with --linke-map" 2 $sol "$dir/flat.pgm" --linke 3 --linke-map "$dir/alb51.pgm" -o "$fdir/x.pfm"
expect_fail "solar: --linke-monthly with --linke-map" 2 $sol "$dir/flat.pgm" --linke-monthly 2,2,3,3,4,4,4,4,3,3,2,2 --linke-map "$dir/alb51.pgm" -o "$fdir/x.pfm"
expect_fail "solar: --albedo with --albedo-map" 2 $sol "$dir/flat.pgm" --albedo 0.3 --albedo-map "$dir/alb51.pgm" -o "$fdir/x.pfm"
# every output against every input (IN, --albedo-map, --linke-map) unless --overwrite, and no
# two outputs one file (or one ASC/EHdr sidecar) ever: the refusals leave every file as it was
"$hfvis" skyview "$dir/flat.pgm" --dirs 4 --quiet -o "$dir/sin.pfm"; cp "$dir/sin.pfm" "$dir/sin_copy.pfm"
"$hfvis" skyview "$dir/flat.pgm" --dirs 4 --quiet -o "$dir/smap.pfm"; cp "$dir/smap.pfm" "$dir/smap_copy.pfm"
sol="solar --latitude 46 --longitude 15 --day 2026-06-21 --dirs 8"
expect_fail "solar: --beam is IN" 1 $sol "$dir/sin.pfm" -o "$fdir/x.pfm" --beam "$dir/sin.pfm"
expect_fail "solar: --sun-hours is IN" 1 $sol "$dir/sin.pfm" -o "$fdir/x.pfm" --sun-hours "$dir/sin.pfm"
expect_fail "solar: -o is the --linke-map" 1 $sol "$dir/sin.pfm" --linke-map "$dir/smap.pfm" -o "$dir/smap.pfm"
expect_fail "solar: --diffuse is the --albedo-map" 1 $sol "$dir/sin.pfm" --albedo-map "$dir/smap.pfm" -o "$fdir/x.pfm" --diffuse "$dir/smap.pfm"
expect_fail "solar: --reflected is the --linke-map" 1 $sol "$dir/sin.pfm" --linke-map "$dir/smap.pfm" -o "$fdir/x.pfm" --reflected "$dir/smap.pfm"
cmp -s "$dir/sin.pfm" "$dir/sin_copy.pfm" && cmp -s "$dir/smap.pfm" "$dir/smap_copy.pfm" &&
  ok "solar: refused outputs leave IN and the maps intact" || bad "solar: an input changed"
expect_fail "solar: -o, --beam and --diffuse one file" 2 $sol "$dir/flat.pgm" -o "$fdir/x.tif" --beam "$fdir/x.tif" --diffuse "$fdir/x.tif"
expect_fail "solar: --beam and --sun-hours one file by another spelling" 2 $sol "$dir/flat.pgm" -o "$fdir/x.tif" --beam "$fdir/b.pfm" --sun-hours "$fdir/./b.pfm"
echo old > "$dir/sold_out.pfm"; ln -s "$dir/sold_out.pfm" "$dir/sold_link.pfm" 2> /dev/null
if [ -L "$dir/sold_link.pfm" ]; then expect_fail "solar: -o and --beam one file through a symbolic link" 2 $sol "$dir/flat.pgm" -o "$dir/sold_out.pfm" --beam "$dir/sold_link.pfm"
  [ "$(cat "$dir/sold_out.pfm")" = old ] && ok "solar: the shared output left as it was" || bad "solar: the shared output was replaced"
else ok "solar outputs through a link: skipped (no ln -s)"; fi
expect_fail "solar: an .asc and a .bil output share their .prj" 2 $sol "$dir/flat.pgm" -o "$fdir/x.bil" --beam "$fdir/x.asc"
expect_fail "solar: --overwrite does not let two outputs share a file" 2 $sol "$dir/flat.pgm" --overwrite -o "$fdir/x.pfm" --beam "$fdir/x.pfm"
cp "$dir/sin.pfm" "$dir/sin_ow.pfm"
expect_ok "solar --overwrite: --beam may replace IN" "$dir/sow_g.pfm" $sol "$dir/sin_ow.pfm" --overwrite --beam "$dir/sin_ow.pfm" -o "$dir/sow_g.pfm"
cmp -s "$dir/sin_ow.pfm" "$dir/sin.pfm" && bad "solar --overwrite: IN not replaced by --beam" || ok "solar --overwrite: IN replaced by --beam"
# what can be known to fail is refused before the run (an ASC output of several bands, an output
# in a directory that does not exist), and OUT is written last: a failing extra output (here a
# directory in its place) leaves it as it was
echo old > "$dir/skeep.tif"
expect_fail "solar: --sun-hours in a directory that does not exist" 1 $sol "$dir/flat.pgm" -o "$dir/skeep.tif" --sun-hours "$dir/no/such/dir/h.tif"
expect_fail "solar: an .asc output of month bands" 2 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --start 2026-01-30 --end 2026-02-02 --bands month --dirs 8 -o "$dir/skeep.tif" --sun-hours "$fdir/h.asc"
expect_fail "solar: -o .asc of day bands" 2 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --start 2026-01-30 --end 2026-02-02 --bands day --dirs 8 -o "$fdir/g.asc"
expect_fail "a skyview OUT in a directory that does not exist" 1 skyview "$dir/flat.pgm" -o "$dir/no/such/dir/x.pfm"
mkdir -p "$dir/sdir.tif"
expect_fail "solar: --sun-hours that cannot be written (a directory)" 1 $sol "$dir/flat.pgm" -o "$dir/skeep.tif" --sun-hours "$dir/sdir.tif"
[ "$(cat "$dir/skeep.tif")" = old ] && ok "solar: failing outputs leave OUT untouched" || bad "solar: OUT replaced by a run that failed"
expect_ok "solar: an .asc output of one band" "$dir/s1.asc" $sol "$dir/flat.pgm" -o "$dir/s1.asc"

# ---- users' tests of the mesh and screen commands (eleventh session) ------------------------
# voxelize --mode surface of the unit cube fitted without padding: the three faces on the grid's
# far side (x, y, z = 1) were dropped (37 of the 56 shell voxels at --res 4; 169 of 296 at 8)
expect_ok "voxelize surface: the cube's far faces" "$dir/us.raw" voxelize "$dir/cube.obj" --res 4 -o "$dir/us.raw"
grep -q ', 56 set' "$dir/stdout" && ok "voxelize surface: the cube's 56 shell voxels, as conservative" || bad "voxelize surface of the cube: $(cat "$dir/stdout")"
"$hfvis" voxelize "$dir/cube.obj" --res 4 --mode conservative --quiet -o "$dir/uc.raw"
cmp -s "$dir/us.raw" "$dir/uc.raw" && ok "voxelize surface of the cube: the conservative shell, voxel for voxel" || bad "voxelize surface of the cube differs from its conservative shell"
for ax in x y z; do
  expect_ok "voxelize surface --axis $ax: both faces" "$dir/ua.raw" voxelize "$dir/cube.obj" --res 4 --axis $ax -o "$dir/ua.raw"
  grep -q ', 32 set' "$dir/stdout" && ok "voxelize surface --axis $ax: 2 faces of 16" || bad "voxelize surface --axis $ax: $(cat "$dir/stdout")"
done
for m in slicing clipping; do
  expect_ok "voxelize surface --method $m: the far faces" "$dir/um.raw" voxelize "$dir/cube.obj" --res 4 --method $m -o "$dir/um.raw"
  grep -q ', 56 set' "$dir/stdout" && ok "voxelize surface --method $m: 56 voxels" || bad "voxelize surface --method $m: $(cat "$dir/stdout")"
done
# --max-memory of visfield and volgi: the estimate took visfield's --positions frequency n for the
# count K and stale defaults (82 positions, 16 directions: 0.16 MiB for the default 4226 x 32^2
# field, 17 MB in f32), and volgi's default --res as 0 voxels (0.0007 MiB for 32^3)
expect_fail "visfield: the default field over --max-memory 8M" 1 visfield "$dir/cube.obj" --format f32 --max-memory 8M -o "$fdir/x.hfvf"
expect_fail "visfield: --positions 4226 --dirs 64 over --max-memory 16M" 1 visfield "$dir/cube.obj" --positions 4226 --dirs 64 --max-memory 16M -o "$fdir/x.hfvf"
expect_ok "visfield: a small field under --max-memory 1M" "$dir/um.hfvf" visfield "$dir/cube.obj" --positions 82 --dirs 8 --max-memory 1M -o "$dir/um.hfvf"
expect_fail "volgi: the default 32^3 grid over --max-memory 1M" 1 volgi --room --size 8x8 --max-memory 1M -o "$fdir/x.pfm"
expect_fail "volgi: --res 128 over --max-memory 256M" 1 volgi --room --size 8x8 --res 128 --max-memory 256M -o "$fdir/x.pfm"
# ssao --near/--far: accepted and ignored with linear depth (exit 0), and planes the library
# rejects (near <= 0, near >= far) reported as "invalid argument", exit 1, after the input was read
{ printf 'Pf\n16 12\n-1\n'; i=0; while [ $i -lt 192 ]; do printf '\000\000\000\077'; i=$((i + 1)); done; } > "$dir/uhalf.pfm"
expect_fail "ssao: --near with linear depth" 2 ssao "$dir/uhalf.pfm" --near 1 -o "$fdir/x.pfm"
expect_fail "ssao: --far with linear depth" 2 ssao "$dir/uhalf.pfm" --depth linear --far 10 -o "$fdir/x.pfm"
expect_fail "ssao: --depth gl with --near > --far" 2 ssao "$dir/uhalf.pfm" --depth gl --near 10 --far 1 -o "$fdir/x.pfm"
expect_fail "ssao: --depth d3d with --near 0 in perspective" 2 ssao "$dir/uhalf.pfm" --depth d3d --near 0 --far 1 -o "$fdir/x.pfm"
expect_ok "ssao: --depth gl, orthographic --near 0" "$dir/ugl.pfm" ssao "$dir/uhalf.pfm" --depth gl --ortho 0.1 --near 0 --far 10 -o "$dir/ugl.pfm"
expect_last_float "ssao: a flat GL depth buffer is open" "$dir/ugl.pfm" 0 1e-6
# a flat mesh at --res 2048 is a 2048 x 2048 x 1 grid (4 MiB) but a 2048^3 .binvox cube: it was
# voxelized, then refused as "invalid argument"; now named before the run, and .raw still works
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n' > "$dir/usq.obj"
expect_fail "voxelize: a .binvox cube past 2^31 voxels" 1 voxelize "$dir/usq.obj" --res 2048 -o "$fdir/x.binvox"
case "$err_first" in *"2048^3"*) ok "voxelize: the .binvox refusal names the cube" ;; *) bad "voxelize .binvox refusal: $err_first" ;; esac
expect_ok "voxelize: the same flat grid as .raw" "$dir/usq.raw" voxelize "$dir/usq.obj" --res 2048 -o "$dir/usq.raw"
[ "$(wc -c < "$dir/usq.raw" | tr -d ' ')" = 4194304 ] && ok "voxelize: 2048 x 2048 x 1 bytes" || bad "voxelize flat .raw size"

# the mends of the review: volgi's zero --up named (it was reported under --eye), an intensity
# beyond float named as such (it said "must be >= 0"), ssao's background depths in its help
expect_fail "volgi: --up 0,0,0" 2 volgi --room --size 8x8 --up 0,0,0 -o "$fdir/x.pfm"
case "$err_first" in *"--up"*zero*) ok "volgi: a zero --up named" ;; *) bad "volgi --up 0,0,0: $err_first" ;; esac
expect_fail "volgi: a light of 1e39" 2 volgi --room --size 8x8 --light point:1,1,1:1e39 -o "$fdir/x.pfm"
case "$err_first" in *finite*3.4e38*) ok "volgi: an intensity beyond float named" ;; *) bad "volgi --light ...:1e39: $err_first" ;; esac
"$hfvis" ssao --help 2>&1 | grep -q "is background" && ok "ssao --help: background depths" || bad "ssao --help does not say which depths are background"

# ---- users' tests of light, indirect, gi, sky, sum, info and azimuths (eleventh session) ----
# --dirs past a command's own limit: --exact past K = 16384 (directions need max(|a|, |b|) <=
# ceil(K/4) <= 4096) ran and failed as "invalid argument" (azimuths: "--azimuth0: not a usable
# azimuth"), gi past 4096 slices the same, solar past 4096 as "an input is out of range
# (latitude 46, longitude 15)", all after reading IN; now refused by name before the run
expect_fail "azimuths --exact --dirs 16385" 2 azimuths --dirs 16385 --exact
case "$err_first" in *"--dirs"*16384*) ok "azimuths --exact --dirs 16385 names --dirs" ;; *) bad "azimuths --exact --dirs 16385: $err_first" ;; esac
"$hfvis" azimuths --dirs 16384 --exact > "$dir/stdout" 2> "$dir/stderr" && [ "$(wc -l < "$dir/stdout" | tr -d ' ')" = 16384 ] \
  && ok "azimuths --exact --dirs 16384: 16384 lines" || bad "azimuths --exact --dirs 16384: $(head -n 1 "$dir/stderr")"
for c in horizon skyview sky; do
  expect_fail "$c --exact --dirs 20000" 2 $c "$dir/flat.pgm" --exact --dirs 20000 -o "$fdir/x.pfm"
done
expect_fail "light --exact --dirs 16385" 2 light "$dir/flat.pgm" --env "$dir/env1.pfm" --exact --dirs 16385 -o "$fdir/x.pfm"
expect_fail "sky --exact --dirs 20000, a part" 2 sky "$dir/flat.pgm" --exact --dirs 20000 --dir-range 0:4 -o "$fdir/x.hfvs"
expect_fail "gi --dirs 4097" 2 gi "$dir/flat.pgm" --dirs 4097 -o "$fdir/x.pfm"
case "$err_first" in *"--dirs"*4096*) ok "gi --dirs 4097 names the limit" ;; *) bad "gi --dirs 4097: $err_first" ;; esac
expect_ok "gi --dirs 4096" "$dir/ug4096.pfm" gi "$dir/flat.pgm" --dirs 4096 -o "$dir/ug4096.pfm"
expect_fail "solar --dirs 4097" 2 solar "$dir/flat.pgm" --latitude 46 --longitude 15 --day 2026-06-21 --dirs 4097 -o "$fdir/x.pfm"
case "$err_first" in *"--dirs"*4096*) ok "solar --dirs 4097 names --dirs" ;; *) bad "solar --dirs 4097: $err_first" ;; esac
# --border-cells was accepted and ignored (exit 0, the same bytes) with an open border (the default)
# and by gi (its pyramid) and visibility (nothing outside the grid is counted or lies between a
# point and a sample); now refused by name. With clamp/wrap the other commands still take it.
expect_fail "sky --border-cells with the default open border" 2 sky "$dir/hill.pgm" --border-cells 5 -o "$fdir/x.pfm"
expect_fail "light --border open --border-cells" 2 light "$dir/hill.pgm" --env "$dir/env1.pfm" --border open --border-cells 5 -o "$fdir/x.pfm"
expect_fail "gi --border clamp --border-cells" 2 gi "$dir/hill.pgm" --border clamp --border-cells 5 -o "$fdir/x.pfm"
expect_fail "visibility --border wrap --border-cells" 2 visibility "$dir/hill.pgm" --border wrap --border-cells 5 -o "$fdir/x.pfm"
expect_ok "sky --border clamp --border-cells 2" "$dir/ubc2.pfm" sky "$dir/hill.pgm" --border clamp --border-cells 2 -o "$dir/ubc2.pfm"
expect_ok "sky --border clamp" "$dir/ubc.pfm" sky "$dir/hill.pgm" --border clamp -o "$dir/ubc.pfm"
cmp -s "$dir/ubc2.pfm" "$dir/ubc.pfm" && bad "sky --border clamp: --border-cells 2 changed nothing" || ok "sky --border clamp: --border-cells 2 changes the result"

rm -rf "$dir"
echo "cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
