#!/bin/sh
# solar_rsun.sh - hfvis_solar_irradiation (r.sun's solar geometry, HFVIS_SUN_RSUN) against GRASS
# r.sun itself: open flat ground and planes tilted 30 deg toward E, N, W, S at latitudes 0, 35,
# 60, 70 and days 1, 80, 172, 355 (68 cases; daily beam, diffuse, reflected and global, step
# 0.25 h, Linke 3, albedo 0.2). Each must agree within TOL_REL (0.5 %, issue 27) of r.sun, or
# within TOL_ABS Wh/m^2 where both are near 0 (polar night, a north slope in winter). The two
# north slopes at 70 N are r.sun's own error (see below) and reported, not compared.
# SKIPs (exit 0) where GRASS (`grass`) is not installed.
# usage: sh test/solar_rsun.sh [SCRATCHDIR]       (about 1-2 minutes: GRASS starts 68 times)
TOL_REL=0.005
TOL_ABS=0.5
command -v grass >/dev/null 2>&1 || { echo "SKIP solar_rsun: grass not installed (Debian: grass-core)"; exit 0; }
CC=${CC:-cc}
dir=${1:-${TMPDIR:-/tmp}}/solar_rsun.$$
rm -rf "$dir"; mkdir -p "$dir" || exit 1
trap 'rm -rf "$dir"' EXIT
root=$(cd "$(dirname "$0")/.." && pwd)
$CC -std=c99 -O2 -ffp-contract=off -o "$dir/driver" "$root/test/solar_rsun_driver.c" \
    "$root/hfvis.c" -lm || { echo "FAIL solar_rsun: driver does not build"; exit 1; }
grass -c EPSG:4326 "$dir/loc" -e >/dev/null 2>&1 || { echo "FAIL solar_rsun: cannot create a GRASS location"; exit 1; }
# One GRASS session runs every r.sun case: a 3 x 3 region of 0.001 deg cells around (lat, 15 E),
# height 0, slope and aspect as values. r.sun 8.2 reads aspect_value as a compass bearing
# (clockwise from north: at 9:00 solar time on day 172 at 35 N a 30 deg plane of aspect_value 90
# gets 879 W/m^2 of beam, 270 gets 298), although its help says "270 is south"; docs/solar.md.
cat > "$dir/cases.sh" <<'EOS'
for lat in 0 35 60 70; do
  g.region n=$(echo "$lat + 0.0015" | bc -l) s=$(echo "$lat - 0.0015" | bc -l) e=15.0015 w=14.9985 res=0.001 --quiet
  r.mapcalc "elev = 0" --overwrite --quiet
  for day in 1 80 172 355; do
    for f in flat E N W S; do
      case $f in flat) sl=0; as=270;; E) sl=30; as=90;; N) sl=30; as=360;; W) sl=30; as=270;; S) sl=30; as=180;; esac
      r.sun -p elevation=elev slope_value=$sl aspect_value=$as day=$day step=0.25 linke_value=3 \
        albedo_value=0.2 beam_rad=b diff_rad=d refl_rad=r glob_rad=g --overwrite --quiet 2>/dev/null
      v=$(r.what map=b,d,r,g coordinates=15,$lat separator=space 2>/dev/null | awk '{print $(NF - 3), $(NF - 2), $(NF - 1), $NF}')
      echo "$lat $day $f $v"
    done
  done
done
EOS
grass "$dir/loc/PERMANENT" --exec sh "$dir/cases.sh" > "$dir/rsun.txt" 2>/dev/null
[ -s "$dir/rsun.txt" ] || { echo "FAIL solar_rsun: r.sun produced nothing"; exit 1; }
passed=0; failed=0; known=0; worst=0
while read -r lat day f rb rd rr rg; do
  [ -n "$rg" ] || { failed=$((failed + 1)); echo "FAIL solar_rsun $lat $day $f: no r.sun value"; continue; }
  sl=30; [ "$f" = flat ] && sl=0
  set -- $("$dir/driver" "$lat" "$day" "$sl" "$f")
  res=$(echo "$rb $rd $rr $rg $1 $2 $3 $4" | awk -v tr=$TOL_REL -v ta=$TOL_ABS '{
    w = 0; ok = 1
    for (i = 1; i <= 4; i++) { r = $i; h = $(i + 4); if (r == "*" ) r = 0; d = h - r; if (d < 0) d = -d
      m = (r > h ? r : h); rel = (m > 0 ? d / m : 0)
      if (d > ta && rel > tr) ok = 0
      if (m > 1 && rel > w) w = rel }
    printf "%d %.5f\n", ok, w }')
  ok=${res% *}; rel=${res#* }
  if [ "$f" = N ] && [ "$lat" -gt 60 ] && [ "$rg" != 0 ]; then
    # r.sun takes the longitude of the plane's equivalent horizontal place with atan where the
    # quadrant needs atan2: on a plane tilted toward the pole by more than the co-latitude its
    # incidence term flips sign (docs/solar.md, errata). hfvis uses the dot product n.s.
    known=$((known + 1)); echo "known solar_rsun lat $lat day $day $f: r.sun $rb $rd $rr $rg, hfvis $1 $2 $3 $4 (r.sun's atan branch)"
    continue
  fi
  worst=$(echo "$worst $rel" | awk '{print ($2 > $1 ? $2 : $1)}')
  if [ "$ok" = 1 ]; then passed=$((passed + 1)); echo "ok   solar_rsun lat $lat day $day $f (r.sun $rg, hfvis $4 Wh/m2; worst term $rel)"
  else failed=$((failed + 1)); echo "FAIL solar_rsun lat $lat day $day $f: r.sun $rb $rd $rr $rg, hfvis $1 $2 $3 $4"; fi
done < "$dir/rsun.txt"
echo "solar_rsun: worst relative difference $worst (tolerance $TOL_REL)"
echo "solar_rsun: $known known r.sun errors (north slopes at 70 N in daylight) not compared"
echo "solar_rsun: $passed passed, $failed failed"
[ "$failed" = 0 ]
