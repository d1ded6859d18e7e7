#!/bin/sh
# cli_test.sh - end-to-end checks of the hfvis command-line tool (DESIGN.md §4): every subcommand
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
printf 'hello, I am not an image\n' > "$dir/garbage.pgm"
{ printf 'Pf\n4 4\n-1\n'; printf "$one$one$one"; } > "$dir/truncated.pfm"

little_endian=0
[ "$(printf '\001\000' | od -An -tu2 | tr -d ' ')" = 1 ] && little_endian=1

# ---- helpers ------------------------------------------------------------------------------
# expect_ok NAME OUT ARGS...: exit 0, nothing on stderr, OUT written.
expect_ok() {
  name=$1; out=$2; shift 2
  rm -f "$out"
  "$hfvis" "$@" > "$dir/stdout" 2> "$dir/stderr"; rc=$?
  if [ "$rc" -ne 0 ]; then bad "$name: exit $rc: $(head -n 3 "$dir/stderr")"
  elif [ -s "$dir/stderr" ]; then bad "$name: unexpected stderr: $(head -n 3 "$dir/stderr")"
  elif [ ! -s "$out" ]; then bad "$name: $out not written"
  else ok "$name"; fi
}
# expect_fail NAME STATUS ARGS...: exit STATUS (1 error, 2 usage), exactly one stderr line that
# starts with "hfvis: ", and nothing created in $fdir (no output, no temporary file).
expect_fail() {
  name=$1; want=$2; shift 2
  "$hfvis" "$@" > "$dir/stdout" 2> "$dir/stderr"; rc=$?
  lines=$(wc -l < "$dir/stderr" | tr -d ' ')
  left=$(ls -A "$fdir")
  if [ "$rc" -ne "$want" ]; then bad "$name: exit $rc, want $want: $(head -n 3 "$dir/stderr")"
  elif [ "$lines" != 1 ] || [ "$(wc -c < "$dir/stderr" | tr -d ' ')" -le 7 ]; then
    bad "$name: want one stderr line, got $lines: $(head -n 3 "$dir/stderr")"
  elif ! head -n 1 "$dir/stderr" | grep -q '^hfvis: '; then bad "$name: stderr line: $(cat "$dir/stderr")"
  elif [ -n "$left" ]; then bad "$name: left behind in $fdir: $left"; rm -rf "${fdir:?}"/* "$fdir"/.[!.]*
  else ok "$name: $(cat "$dir/stderr")"; fi
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
expect_line2() { # NAME FILE WANT: the second header line (PFM dimensions)
  got=$(head -n 2 "$2" | tail -n 1)
  if [ "$got" = "$3" ]; then ok "$1"; else bad "$1: header line 2 '$got', want '$3'"; fi
}

# ---- help ---------------------------------------------------------------------------------
if "$hfvis" --help > "$dir/stdout" 2> "$dir/stderr" && grep -q '^usage: hfvis' "$dir/stdout" && [ ! -s "$dir/stderr" ]
then ok "--help"; else bad "--help"; fi
for c in horizon skyview sky shadow light normals; do
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
expect_ok "shadow --math --sun-radius" "$dir/sh2.pgm" shadow "$h" --math --sun-azimuth -45 --sun-elevation 10 --sun-radius 2 -o "$dir/sh2.pgm"
expect_ok "light grey env" "$dir/l1.pfm" light "$h" --env "$dir/env1.pfm" -o "$dir/l1.pfm"
expect_ok "light rgb env lp" "$dir/l3.pfm" light "$h" --env "$dir/env3.pfm" --method lp --albedo 0.7 -o "$dir/l3.pfm"
head -n 1 "$dir/l3.pfm" | grep -q '^PF' && ok "light rgb env writes PF" || bad "light rgb env writes PF"
expect_ok "light pgm" "$dir/l3.pgm" light "$h" --env "$dir/env3.pfm" -o "$dir/l3.pgm"
expect_ok "normals" "$dir/n.pfm" normals "$h" --nodata 228 -o "$dir/n.pfm"
head -n 1 "$dir/n.pfm" | grep -q '^PF' && ok "normals writes PF" || bad "normals writes PF"
expect_ok "normals pgm" "$dir/n.pgm" normals "$h" -o "$dir/n.pgm"
expect_ok "--quiet, -- before IN" "$dir/q.pfm" skyview --quiet -o "$dir/q.pfm" -- "$h"
expect_ok "a PFM input (the tool's own output)" "$dir/svf2.pfm" skyview "$dir/svf.pfm" -o "$dir/svf2.pfm"

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
expect_bytes "shadow flat, sun in the west below the horizon = 0" "$dir/fd.pgm" 2 "00 00"
expect_ok "normals flat" "$dir/fn.pfm" normals "$f" --zscale 3 -o "$dir/fn.pfm"
expect_bytes "normals flat: z = 1" "$dir/fn.pfm" 4 "00 00 80 3f"
# horizon, --dirs 4 --degrees: plane 0 looks east, so (6, 0) sees flat ground (0 deg) and (7, 0)
# nothing (-90 deg); with --compass plane 0 looks north, off the grid for both; with --border
# clamp the flat ground extends and both see 0 deg.
expect_ok "horizon flat" "$dir/fh.pfm" horizon "$f" --dirs 4 --degrees -o "$dir/fh.pfm"
expect_bytes "horizon flat east: 0, -90 deg" "$dir/fh.pfm" 8 "00 00 00 00 00 00 b4 c2" "00 00 00 80 00 00 b4 c2"
expect_ok "horizon flat --compass" "$dir/fc.pfm" horizon "$f" --dirs 4 --degrees --compass -o "$dir/fc.pfm"
expect_bytes "horizon flat --compass north: -90, -90 deg" "$dir/fc.pfm" 8 "00 00 b4 c2 00 00 b4 c2"
expect_ok "horizon flat --border clamp" "$dir/fb.pfm" horizon "$f" --dirs 4 --border clamp -o "$dir/fb.pfm"
expect_bytes "horizon flat clamp east: 0, 0" "$dir/fb.pfm" 8 "00 00 00 00 00 00 00 00" \
  "00 00 00 80 00 00 00 00" "00 00 00 00 00 00 00 80" "00 00 00 80 00 00 00 80"
expect_ok "light flat, uniform env" "$dir/fl.pfm" light "$f" --env "$dir/env1.pfm" -o "$dir/fl.pfm"
expect_last_float "light flat under radiance 1 = 1" "$dir/fl.pfm" 1 1e-4
expect_ok "sky flat" "$dir/fk.pfm" sky "$f" --sky 2 --albedo 0.25 -o "$dir/fk.pfm"
expect_last_float "sky flat = albedo * sky" "$dir/fk.pfm" 0.5 1e-4
expect_ok "--nodata makes holes" "$dir/fnd.pfm" skyview "$f" --nodata 100 -o "$dir/fnd.pfm"
expect_bytes "--nodata hole is NaN" "$dir/fnd.pfm" 4 "00 00 c0 7f" "00 00 c0 ff"

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
expect_fail "horizon over the size limit" 1 horizon "$dir/big.pgm" --dirs 65536 -o "$o"
grep -q 'HFVIS_ERR_LIMIT' "$dir/stderr" && ok "horizon limit names HFVIS_ERR_LIMIT" || bad "horizon limit names HFVIS_ERR_LIMIT"

# A failed run leaves an existing OUT untouched.
printf 'old\n' > "$dir/keep.pfm"
"$hfvis" skyview "$dir/garbage.pgm" -o "$dir/keep.pfm" 2> /dev/null
[ "$(cat "$dir/keep.pfm")" = old ] && ok "failed run keeps the old OUT" || bad "failed run keeps the old OUT"

rm -rf "$dir"
echo "cli: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
