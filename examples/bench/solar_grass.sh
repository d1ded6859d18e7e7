#!/bin/sh
# solar_grass.sh - GRASS's side of bench_solar (make bench): times r.sun on a DEM, one day (172,
# 15-minute steps, Linke 3, albedo 0.2, nprocs=1) with its own shadowing, and r.horizon at 5 deg
# steps (72 maps) followed by r.sun reading them. Prints "rsun_shadow S", "rhorizon S",
# "rsun_horizon S" (seconds, wall clock) and r.sun's mean global as "rsun_mean WH"; or one
# "SKIP reason" line where GRASS (`grass`, Debian: grass-core) is absent.
# usage: sh solar_grass.sh DEM.asc EPSG SCRATCHDIR
command -v grass >/dev/null 2>&1 || { echo "SKIP grass not installed (Debian: grass-core)"; exit 0; }
[ $# -eq 3 ] || { echo "SKIP usage: solar_grass.sh DEM.asc EPSG SCRATCHDIR"; exit 0; }
dem=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
dir=$3/solar_grass.$$
rm -rf "$dir"; mkdir -p "$dir" || { echo "SKIP cannot create $dir"; exit 0; }
trap 'rm -rf "$dir"' EXIT
grass -c "EPSG:$2" "$dir/loc" -e >/dev/null 2>&1 || { echo "SKIP cannot create a GRASS location"; exit 0; }
cat > "$dir/job.sh" <<EOS
now() { date +%s.%N; }
r.in.gdal -o input="$dem" output=dem --quiet >/dev/null 2>&1 || { echo "SKIP r.in.gdal failed"; exit 0; }
g.region raster=dem --quiet
r.slope.aspect elevation=dem slope=sl aspect=as --quiet >/dev/null 2>&1
t0=\$(now)
r.sun elevation=dem slope=sl aspect=as day=172 step=0.25 linke_value=3 albedo_value=0.2 glob_rad=g nprocs=1 --quiet >/dev/null 2>&1
t1=\$(now)
r.horizon elevation=dem step=5 output=hor --quiet >/dev/null 2>&1
t2=\$(now)
r.sun elevation=dem slope=sl aspect=as horizon_basename=hor horizon_step=5 day=172 step=0.25 linke_value=3 albedo_value=0.2 glob_rad=g2 nprocs=1 --quiet >/dev/null 2>&1
t3=\$(now)
echo "rsun_shadow \$(echo "\$t1 - \$t0" | bc -l)"
echo "rhorizon \$(echo "\$t2 - \$t1" | bc -l)"
echo "rsun_horizon \$(echo "\$t3 - \$t2" | bc -l)"
echo "rsun_mean \$(r.univar -g map=g 2>/dev/null | sed -n 's/^mean=//p')"
EOS
grass "$dir/loc/PERMANENT" --exec sh "$dir/job.sh" 2>/dev/null
