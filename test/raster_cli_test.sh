#!/bin/sh
# raster_cli_test.sh - the hfvis tool with GIS rasters (examples/raster_io.h): ASC and EHdr in and
# out against the PGM route bit for bit, the cell size and NoData taken from the raster, --cell
# overriding with a note, the no-georeference note, geographic CRS refused, --band; then, when
# GDAL is installed, GeoTIFFs written by gdal_translate (DEFLATE/LZW/PackBits, tiled, predictors,
# BigTIFF, big-endian) read bit for bit and hfvis's GeoTIFF/EHdr/ASC outputs read by GDAL with the
# input's CRS, geotransform, NoData and values (gdalinfo, gdal_translate, gdalcompare.py);
# "SKIP gdal" without it.
# usage: sh test/raster_cli_test.sh BUILD/hfvis SCRATCHDIR
hfvis=$1
[ -n "$hfvis" ] && [ -x "$hfvis" ] || { echo "usage: sh test/raster_cli_test.sh BUILD/hfvis SCRATCHDIR"; exit 2; }
dir=${2:-${TMPDIR:-/tmp}}/raster_cli_test.$$
rm -rf "$dir"; mkdir -p "$dir" || exit 1
passed=0; failed=0
ok()  { passed=$((passed + 1)); echo "ok   raster $1"; }
bad() { failed=$((failed + 1)); echo "FAIL raster $1"; }
# run NAME ARGS...: exit 0; stderr kept in $dir/err
run() { name=$1; shift; if "$hfvis" "$@" > /dev/null 2> "$dir/err"; then return 0; fi
        bad "$name: exit $?: $(head -n 2 "$dir/err")"; return 1; }
# fails NAME ARGS...: exit 1 with exactly one stderr line
fails() { name=$1; shift; "$hfvis" "$@" > /dev/null 2> "$dir/err"; rc=$?
          if [ "$rc" -eq 1 ] && [ "$(wc -l < "$dir/err" | tr -d ' ')" = 1 ]; then ok "$name: $(cat "$dir/err")"
          else bad "$name: exit $rc, stderr: $(head -n 3 "$dir/err")"; fi; }
# same NAME A B: files identical
same() { if cmp -s "$2" "$3"; then ok "$1"; else bad "$1: $2 and $3 differ"; fi; }

# ---- inputs: one 41 x 33 integer terrain with a NoData hole, as PGM (values only) and ASC ------
awk 'BEGIN { w = 41; h = 33; print "P2"; print w, h; print 65535
  for (y = 0; y < h; y++) { s = ""; for (x = 0; x < w; x++) {
    v = int(3000 + 900 * sin(x / 5) * cos(y / 6) + 13 * x); if (x == 7 && y == 9) v = 0; s = s " " v }
    print s } }' > "$dir/dem.pgm"
{ printf 'ncols 41\nnrows 33\nxllcorner 500000\nyllcorner 4100000\ncellsize 30\nNODATA_value 0\n'
  tail -n +4 "$dir/dem.pgm"; } > "$dir/dem.asc"
printf 'PROJCS["WGS 84 / UTM zone 33N",GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],PARAMETER["latitude_of_origin",0],PARAMETER["central_meridian",15],PARAMETER["scale_factor",0.9996],PARAMETER["false_easting",500000],PARAMETER["false_northing",0],UNIT["metre",1],AUTHORITY["EPSG","32633"]]\n' > "$dir/dem.prj"

# ---- the PGM route and the raster routes agree bit for bit ------------------------------------
run "skyview pgm route" skyview "$dir/dem.pgm" --cell 30 --nodata 0 --dirs 8 -o "$dir/ref.flt" && ok "skyview pgm route -> .flt"
run "skyview asc" skyview "$dir/dem.asc" --dirs 8 -o "$dir/asc.flt" && same "skyview dem.asc = pgm route (cell 30, NoData from the grid)" "$dir/ref.flt" "$dir/asc.flt"
[ -s "$dir/err" ] && bad "georeferenced input printed: $(cat "$dir/err")"
grep -q '^NODATA 0$' "$dir/asc.hdr" && grep -q '^XDIM 30$' "$dir/asc.hdr" && grep -q '^ULXMAP 500015$' "$dir/asc.hdr" \
  && ok ".hdr carries NoData, cell and corner" || bad ".hdr: $(cat "$dir/asc.hdr")"
[ -s "$dir/asc.prj" ] && same ".prj carried to the output" "$dir/dem.prj" "$dir/asc.prj"
run "skyview flt" skyview "$dir/asc.flt" --dirs 8 -o "$dir/flt.flt" && ok "an .flt output reads back as input"
# viewshed --observer in map coordinates of a georeferenced input: the centre of column 20, row 16
# of dem.asc is X = 500000 + 20.5*30, Y = 4100000 + (33 - 16.5)*30 (the rows run southward)
run "viewshed map" viewshed "$dir/dem.asc" --observer 500615,4100495 -o "$dir/vs_map.flt" \
  && run "viewshed grid" viewshed "$dir/dem.asc" --observer-grid 20,16 -o "$dir/vs_grid.flt" \
  && same "viewshed --observer in the raster's map coordinates = --observer-grid" "$dir/vs_map.flt" "$dir/vs_grid.flt"
run "skyview asc -> asc" skyview "$dir/dem.asc" --dirs 8 -o "$dir/svf.asc" && run "asc -> flt" skyview "$dir/dem.asc" --dirs 8 -o "$dir/svf2.flt" \
  && grep -q '^NODATA_value 0$' "$dir/svf.asc" && grep -q '^cellsize 30$' "$dir/svf.asc" && ok "asc output header"
run "skyview asc -> tif" skyview "$dir/dem.asc" --dirs 8 -o "$dir/svf.tif" && ok "skyview dem.asc -o svf.tif"
run "skyview tif (hfvis-written) -> flt" skyview "$dir/svf.tif" --dirs 8 -o "$dir/svf_of_svf.flt" && ok "hfvis reads its own GeoTIFF"
run "horizon asc -> tif bands" horizon "$dir/dem.asc" --dirs 4 -o "$dir/h.tif" && run "horizon -> bil" horizon "$dir/dem.asc" --dirs 4 -o "$dir/h.bil" \
  && grep -q '^NBANDS 4$' "$dir/h.hdr" && ok "horizon: 4 planes -> 4 bands"
run "band 3 of the horizon GeoTIFF" skyview "$dir/h.tif" --band 3 --dirs 4 --cell 30 -o "$dir/b3.flt" && ok "--band 3"
fails "--band beyond the bands" skyview "$dir/h.tif" --band 5 -o "$dir/x.flt"
fails "--band on a PGM" skyview "$dir/dem.pgm" --band 2 -o "$dir/x.flt"

# ---- the CRS across formats: a .prj into GeoKeys (its EPSG code, else the WKT as an ESRI PE
# string) and a PE string back into a .prj ------------------------------------------------------
run "asc + .prj -> tif" skyview "$dir/dem.asc" --dirs 4 -o "$dir/prj.tif" && "$hfvis" info "$dir/prj.tif" | grep -qx 'crs projected EPSG:32633' \
  && ok "asc + .prj (EPSG 32633) -> tif: ProjectedCSTypeGeoKey 32633" || bad "asc -> tif CRS: $("$hfvis" info "$dir/prj.tif" | grep crs)"
cp "$dir/dem.asc" "$dir/esri.asc"
printf 'PROJCS["WGS_1984_UTM_Zone_33N",GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984",SPHEROID["WGS_1984",6378137.0,298.257223563]],PRIMEM["Greenwich",0.0],UNIT["Degree",0.0174532925199433]],PROJECTION["Transverse_Mercator"],PARAMETER["False_Easting",500000.0],PARAMETER["False_Northing",0.0],PARAMETER["Central_Meridian",15.0],PARAMETER["Scale_Factor",0.9996],PARAMETER["Latitude_Of_Origin",0.0],UNIT["Meter",1.0]]\n' > "$dir/esri.prj"
run "esri .prj -> tif" skyview "$dir/esri.asc" --dirs 4 -o "$dir/pe.tif" && "$hfvis" info "$dir/pe.tif" | grep -qx 'crs projected' \
  && ok "asc + ESRI .prj (no EPSG code) -> tif: projected, read back from the PE string" || bad "PE string tif: $("$hfvis" info "$dir/pe.tif" | grep crs)"
run "pe tif -> asc" skyview "$dir/pe.tif" --dirs 4 -o "$dir/pe.asc" && same "the PE string's WKT back into a .prj, as it was" "$dir/esri.prj" "$dir/pe.prj"
run "pe tif -> flt" skyview "$dir/pe.tif" --dirs 4 -o "$dir/pe2.flt" && same "... and beside an EHdr output" "$dir/esri.prj" "$dir/pe2.prj"
run "epsg tif -> asc" skyview "$dir/prj.tif" --dirs 4 -o "$dir/ep.asc" && grep -q 'UTM zone 33N.*AUTHORITY\["EPSG","32633"\]\]$' "$dir/ep.prj" \
  && ok "a CRS given by an EPSG code alone (UTM 33N) gets its WKT in a .prj" || bad "EPSG-only tif -> asc: .prj $(cat "$dir/ep.prj" 2>&1)"
if command -v gdalsrsinfo > /dev/null 2>&1; then
  gdalsrsinfo -e "$dir/ep.prj" 2>&1 | grep -q 'EPSG:32633' && ok "GDAL identifies the written .prj as EPSG:32633" \
    || bad "gdalsrsinfo of the UTM .prj: $(gdalsrsinfo -e "$dir/ep.prj" 2>&1 | head -3)"
else echo "SKIP gdalsrsinfo not found (.prj identification)"; fi
cp "$dir/dem.asc" "$dir/geog.asc"
printf 'GEOGCS["GCS_WGS_1984",DATUM["D_WGS_1984",SPHEROID["WGS_1984",6378137.0,298.257223563]],PRIMEM["Greenwich",0.0],UNIT["Degree",0.0174532925199433]]\n' > "$dir/geog.prj"
run "geographic .prj -> tif" skyview "$dir/geog.asc" --cell 30 --dirs 4 -o "$dir/geog.tif" && \
  fails "a GeoTIFF with a geographic PE string is refused as the .prj was" skyview "$dir/geog.tif" -o "$dir/x.flt"

# ---- orientation: the same terrain stored south-up (EHdr YDIM < 0) and mirrored (XDIM < 0) ---
# 16-bit EHdr grids of dem.pgm's heights, rows (or columns) reversed in the file; the outputs
# (north-up for EHdr) equal those of the north-up grid bit for bit, and a GeoTIFF written from
# the south-up input is south-up again and reads back to the same raster
bil16() { # bil16 NAME FLIPX FLIPY: dem.pgm's heights as NAME.bil (unsigned 16-bit, little endian)
  printf "$(tail -n +4 "$dir/dem.pgm" | awk -v fx="$2" -v fy="$3" '{ for (i = 1; i <= NF; i++) v[NR - 1, i - 1] = $i }
    END { w = 41; h = 33; for (y = 0; y < h; y++) for (x = 0; x < w; x++) {
      t = v[fy ? h - 1 - y : y, fx ? w - 1 - x : x]; printf "\\%03o\\%03o", t % 256, int(t / 256) } }')" > "$dir/$1.bil"
  printf 'NROWS 33\nNCOLS 41\nNBITS 16\nPIXELTYPE UNSIGNEDINT\nBYTEORDER I\nNODATA 0\nULXMAP %s\nULYMAP %s\nXDIM %s\nYDIM %s\n' \
    "$([ "$2" = 1 ] && echo 501215 || echo 500015)" "$([ "$3" = 1 ] && echo 4100015 || echo 4100975)" \
    "$([ "$2" = 1 ] && echo -30 || echo 30)" "$([ "$3" = 1 ] && echo -30 || echo 30)" > "$dir/$1.hdr"; }
bil16 nu 0 0; bil16 su 0 1; bil16 mi 1 0
for c in hillshade skyview; do
  f=--dirs=8; [ "$c" = hillshade ] && f=--sun-azimuth=135 # the flags each command takes
  run "$c north-up" $c "$dir/nu.bil" $f -o "$dir/o_nu.flt" && run "$c south-up" $c "$dir/su.bil" $f -o "$dir/o_su.flt" \
    && run "$c mirrored" $c "$dir/mi.bil" $f -o "$dir/o_mi.flt" \
    && same "$c: south-up EHdr (YDIM -30) = north-up, bit for bit" "$dir/o_nu.flt" "$dir/o_su.flt" \
    && same "$c: mirrored EHdr (XDIM -30) = north-up, bit for bit" "$dir/o_nu.flt" "$dir/o_mi.flt"
done
run "south-up -> tif" skyview "$dir/su.bil" --dirs 8 -o "$dir/su.tif" && run "north-up -> tif" skyview "$dir/nu.bil" --dirs 8 -o "$dir/nu.tif" \
  && run "south-up tif in" hillshade "$dir/su.tif" -o "$dir/su2.flt" && run "north-up tif in" hillshade "$dir/nu.tif" -o "$dir/nu2.flt" \
  && same "a GeoTIFF written from a south-up input reads back as the same raster" "$dir/nu2.flt" "$dir/su2.flt"
if command -v gdalinfo > /dev/null 2>&1; then
  gdalinfo "$dir/su.tif" | grep -q 'Pixel Size = (30.000000000000000,30.000000000000000)' \
    && gdalinfo "$dir/su.tif" | grep -q 'Origin = (500000.000000000000000,4100000.000000000000000)' \
    && ok "GDAL: the GeoTIFF of a south-up input is stored south-up (origin at the south-west corner)" \
    || bad "south-up GeoTIFF as GDAL sees it: $(gdalinfo "$dir/su.tif" | grep -E 'Origin|Pixel Size')"
else echo "SKIP gdalinfo not found (south-up GeoTIFF check)"; fi

# ---- horizon azimuths: the directions actually used, in file names and band descriptions ------
# exact rays at K = 24 use the rational direction (4, 1) for the nominal 15 deg: 14.036 deg
run "horizon --exact --split" horizon "$dir/dem.asc" --dirs 24 --exact --split -o "$dir/hx.flt" \
  && [ -f "$dir/hx_014_036.flt" ] && [ ! -f "$dir/hx_015.flt" ] && [ -f "$dir/hx_045.flt" ] \
  && ok "exact --split names each file by the azimuth used (hx_014_036, not hx_015)" \
  || bad "exact split names: $(ls "$dir"/hx_0* 2>/dev/null | head -3 | tr '\n' ' ')"
run "horizon lattice --split" horizon "$dir/dem.asc" --dirs 24 --split -o "$dir/hl.flt" \
  && [ -f "$dir/hl_015.flt" ] && ok "lattice --split keeps the nominal azimuths (hl_015)" || bad "lattice split names"
run "horizon --exact tif" horizon "$dir/dem.asc" --dirs 24 --exact -o "$dir/hx.tif"
if command -v gdalinfo > /dev/null 2>&1; then
  info=$(gdalinfo "$dir/hx.tif")
  echo "$info" | grep -q 'Description = azimuth 14.036 deg compass' && echo "$info" | grep -q 'AZIMUTH=14.036243' \
    && echo "$info" | grep -q 'CONVENTION=compass' && echo "$info" | grep -q 'RAYS=exact' \
    && [ "$(echo "$info" | grep -c 'Description = azimuth')" = 24 ] \
    && ok "GDAL: a horizon GeoTIFF names each band's azimuth (24 bands), the convention and the rays" \
    || bad "horizon band descriptions as GDAL sees them: $(echo "$info" | grep -m 3 -E 'Description|AZIMUTH')"
else echo "SKIP gdalinfo not found (horizon band descriptions)"; fi

# ---- notes on stderr ------------------------------------------------------------------------
run "pgm without --cell" skyview "$dir/dem.pgm" --dirs 4 -o "$dir/n.flt" && grep -q '^hfvis: note: .*cell size: using 1' "$dir/err" \
  && [ "$(wc -l < "$dir/err" | tr -d ' ')" = 1 ] && ok "no cell size: one note line" || bad "no-cell note: $(cat "$dir/err")"
run "pgm --quiet" skyview "$dir/dem.pgm" --dirs 4 --quiet -o "$dir/n.flt" && [ ! -s "$dir/err" ] && ok "--quiet drops the note" || bad "--quiet: $(cat "$dir/err")"
run "asc --cell" skyview "$dir/dem.asc" --dirs 4 --cell 10 -o "$dir/n.flt" && grep -q '^hfvis: note: --cell 10 overrides the cell size 30' "$dir/err" \
  && ok "--cell overrides with a note" || bad "--cell override note: $(cat "$dir/err")"

# ---- refused ------------------------------------------------------------------------------
cp "$dir/dem.asc" "$dir/geo.asc"
printf 'GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433]]\n' > "$dir/geo.prj"
fails "geographic CRS refused" skyview "$dir/geo.asc" -o "$dir/x.flt"
grep -q 'gdalwarp -t_srs' "$dir/err" && ok "the refusal says how to reproject" || bad "no gdalwarp hint: $(cat "$dir/err")"
run "geographic with --cell" skyview "$dir/geo.asc" --cell 30 --dirs 4 -o "$dir/g.flt" && ok "geographic accepted with --cell in metres"
printf 'ncols 2\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\n1 2 3\n' > "$dir/bad.asc"
fails "asc with too many values" skyview "$dir/bad.asc" -o "$dir/x.flt"
printf 'II*\000\010\000\000\000\377\377' > "$dir/bad.tif"
fails "truncated TIFF" skyview "$dir/bad.tif" -o "$dir/x.flt"
fails "an ASC output of several bands" horizon "$dir/dem.asc" --dirs 2 -o "$dir/x.asc"
ls "$dir"/x.* > /dev/null 2>&1 && bad "a failed run left an output" || ok "failed runs leave no output"

# ---- GDAL interop -------------------------------------------------------------------------
if command -v gdal_translate > /dev/null 2>&1 && command -v gdalinfo > /dev/null 2>&1; then
  gt() { gdal_translate -q "$@" 2> "$dir/gerr" || bad "gdal_translate $*: $(cat "$dir/gerr")"; }
  gt -a_srs EPSG:32633 -ot Float32 "$dir/dem.asc" "$dir/base.tif"
  n=0
  for opts in "-co COMPRESS=DEFLATE -co TILED=YES -co BLOCKXSIZE=16 -co BLOCKYSIZE=16" \
              "-co COMPRESS=DEFLATE -co PREDICTOR=3 -co TILED=YES" "-co COMPRESS=LZW -co PREDICTOR=3" \
              "-co COMPRESS=LZW" "-co COMPRESS=PACKBITS" "-co BIGTIFF=YES -co COMPRESS=DEFLATE -co TILED=YES" \
              "-co ENDIANNESS=BIG -co COMPRESS=DEFLATE -co PREDICTOR=3" "-ot Int16 -co COMPRESS=DEFLATE -co PREDICTOR=2" \
              "-ot UInt16 -co COMPRESS=LZW -co PREDICTOR=2 -co TILED=YES" "-ot Int32 -co ENDIANNESS=BIG -co COMPRESS=LZW -co PREDICTOR=2" \
              "-ot Float64 -co COMPRESS=DEFLATE -co PREDICTOR=3" "-ot Float64 -co BIGTIFF=YES -co ENDIANNESS=BIG"; do
    n=$((n + 1))
    # shellcheck disable=SC2086 # $opts is a list of options
    gt $opts "$dir/base.tif" "$dir/g$n.tif"
    if "$hfvis" skyview "$dir/g$n.tif" --dirs 8 -o "$dir/g$n.flt" > /dev/null 2> "$dir/err"; then
      same "GDAL GeoTIFF ($opts) = pgm route" "$dir/ref.flt" "$dir/g$n.flt"
    else bad "GDAL GeoTIFF ($opts): $(cat "$dir/err")"; fi
  done
  # the issue's case: skyview dem.tif -o svf.tif on a GDAL DEFLATE tiled GeoTIFF with NoData
  gt -co COMPRESS=DEFLATE -co TILED=YES -co BLOCKXSIZE=16 -co BLOCKYSIZE=16 "$dir/base.tif" "$dir/dem.tif"
  if run "skyview dem.tif -o svf.tif" skyview "$dir/dem.tif" --dirs 8 -o "$dir/svf.tif"; then
    gdalinfo "$dir/dem.tif" > "$dir/in.info" 2>&1; gdalinfo "$dir/svf.tif" > "$dir/out.info" 2>&1
    for key in 'Origin =' 'Pixel Size =' 'NoData Value=' 'ID\["EPSG",32633\]\]$' 'Size is'; do
      a=$(grep "$key" "$dir/in.info"); b=$(grep "$key" "$dir/out.info")
      if [ -n "$a" ] && [ "$a" = "$b" ]; then ok "gdalinfo svf.tif: same '$a'"; else bad "gdalinfo '$key': in '$a', out '$b'"; fi
    done
    grep -qi 'warning\|error' "$dir/out.info" && bad "gdalinfo complains: $(grep -i 'warning\|error' "$dir/out.info")"
    gt -of EHdr "$dir/svf.tif" "$dir/svf_gdal.flt"
    same "svf.tif through GDAL = pgm route bit for bit" "$dir/ref.flt" "$dir/svf_gdal.flt"
    if command -v gdalcompare.py > /dev/null 2>&1; then
      gdalcompare.py "$dir/asc.flt" "$dir/svf.tif" > "$dir/cmp" 2>&1
      grep -q 'Pixels Differing: [1-9]' "$dir/cmp" && bad "gdalcompare: $(grep Differ "$dir/cmp")" || ok "gdalcompare.py: pixels equal"
    else echo "SKIP gdalcompare.py not found"; fi
  fi
  # hfvis's outputs in every format and option read by GDAL
  gt -of EHdr "$dir/svf.asc" "$dir/asc_gdal.flt" && cmp -s "$dir/asc_gdal.flt" "$dir/svf2.flt" \
    && ok "GDAL reads hfvis's ASC (%.9g round trips)" || bad "GDAL ASC read differs"
  gdalinfo "$dir/svf.asc" | grep -q 'EPSG",32633' && ok "GDAL sees the .prj carried with the ASC" || bad "ASC .prj not seen by GDAL"
  gdalinfo "$dir/prj.tif" | grep -q 'ID\["EPSG",32633\]' && ok "GDAL sees EPSG:32633 in the GeoTIFF of an ASC + .prj" \
    || bad "GDAL: no EPSG:32633 in prj.tif"
  gdalinfo "$dir/pe.tif" > "$dir/pe.info" 2>&1
  grep -q 'Transverse Mercator' "$dir/pe.info" && grep -q 'Longitude of natural origin",15' "$dir/pe.info" \
    && ! grep -qi 'warning\|error' "$dir/pe.info" && ok "GDAL reads the ESRI PE string: Transverse Mercator, central meridian 15" \
    || bad "GDAL on the PE string: $(sed -n 3,6p "$dir/pe.info")"
  gt -of EHdr "$dir/asc.flt" "$dir/flt_gdal.flt" && same "GDAL reads hfvis's EHdr .flt" "$dir/asc.flt" "$dir/flt_gdal.flt"
  gt -of EHdr "$dir/h.tif" "$dir/h_gdal.bil" && same "GDAL reads the 4-band horizon GeoTIFF = hfvis's BIL" "$dir/h.bil" "$dir/h_gdal.bil"
  gdalinfo "$dir/h.tif" | grep -c '^Band ' | grep -qx 4 && ok "gdalinfo: 4 bands" || bad "horizon GeoTIFF bands"
  # integral outputs: the smallest integer type; NoData moved off the values when it collides
  if run "viewshed -> tif" viewshed "$dir/dem.asc" --observer-grid 20,16 -o "$dir/vs.tif"; then
    grep -q "input's NoData 0 is a value of this output" "$dir/err" && ok "NoData colliding with a viewshed value: a note" \
      || bad "no collision note: $(cat "$dir/err")"
    gdalinfo -stats "$dir/vs.tif" > "$dir/vs.info" 2>&1
    grep -q 'Type=Byte' "$dir/vs.info" && grep -q 'NoData Value=2$' "$dir/vs.info" && grep -q 'STATISTICS_MAXIMUM=1$' "$dir/vs.info" \
      && grep -q 'STATISTICS_MINIMUM=0$' "$dir/vs.info" && ok "viewshed GeoTIFF: Byte, values 0..1, NoData 2" \
      || bad "viewshed GeoTIFF: $(grep -E 'Type|NoData|STATISTICS_M' "$dir/vs.info")"
    # gdalinfo -stats left vs.tif.aux.xml with the statistics of these values: a new vs.tif
    # removes it (GDAL would show the old statistics beside the new values)
    if [ -f "$dir/vs.tif.aux.xml" ] && run "viewshed -> tif again" viewshed "$dir/dem.asc" --observer-grid 5,5 -o "$dir/vs.tif"; then
      [ -e "$dir/vs.tif.aux.xml" ] && bad "the stale vs.tif.aux.xml of gdalinfo -stats was left" \
        || ok "a new vs.tif removes the vs.tif.aux.xml of gdalinfo -stats"
    else echo "SKIP gdalinfo -stats wrote no .aux.xml"; fi
  fi
  # solar's site from the CRS of GDAL-written GeoTIFFs: NAD83 and NAD83(2011) UTM by their EPSG
  # codes, a custom Transverse Mercator by its projection GeoKeys (the centre against
  # gdaltransform); EPSG codes of Transverse Mercators without their parameters in the file
  # (NZTM, Slovenia's D96/TM) refused, not guessed at
  if command -v gdaltransform > /dev/null 2>&1; then
    gt -a_srs EPSG:32613 -a_ullr 440000 4460000 443690 4457030 "$dir/dem.asc" "$dir/tm_base.tif"
    for crs in EPSG:26913 EPSG:6342 "+proj=tmerc +lat_0=0 +lon_0=15 +k=0.9999 +x_0=500000 +y_0=-5000000 +ellps=GRS80 +units=m"; do
      gt -a_srs "$crs" "$dir/tm_base.tif" "$dir/tm.tif"
      want=$(echo "20.5 16.5" | gdaltransform -t_srs EPSG:4326 "$dir/tm.tif" | awk '{ printf "%.6f %.6f", $2, $1 }')
      if "$hfvis" solar "$dir/tm.tif" --day 2026-06-21 --dirs 8 --progress -o "$dir/tm_out.tif" > /dev/null 2> "$dir/err"; then
        got=$(sed -n 's/^hfvis solar: site \([-0-9.]*\), \([-0-9.]*\) .*/\1 \2/p' "$dir/err")
        echo "$got $want" | awk 'NF == 4 { d1 = $1 - $3; d2 = $2 - $4; exit !(d1 * d1 + d2 * d2 < 1e-8) } NF != 4 { exit 1 }' \
          && ok "solar site from $crs: $got (gdaltransform $want)" \
          || bad "solar site from $crs: '$got', gdaltransform '$want'"
      else
        bad "solar on $crs: $(head -n 2 "$dir/err")"
      fi
    done
    for crs in EPSG:2193 EPSG:3794; do
      gt -a_srs "$crs" "$dir/tm_base.tif" "$dir/tm.tif"
      fails "solar on $crs (no Transverse Mercator parameters in the file)" solar "$dir/tm.tif" --day 2026-06-21 --dirs 8 -o "$dir/tm_out.tif"
      grep -q "latitude is unknown: $crs" "$dir/err" || bad "solar on $crs: $(cat "$dir/err")"
    done
  else
    echo "SKIP gdaltransform: not installed"
  fi
  # solar's --linke-map and --albedo-map read as IN is: GDAL's GeoTIFFs (LZW, tiled; DEFLATE with
  # the floating-point predictor) give the ASC maps' output byte for byte
  awk 'NR <= 6 { print; next } { s = ""; for (i = 1; i <= NF; i++) s = s " " (i % 3 ? 2.5 : 3.25); print s }' "$dir/dem.asc" > "$dir/lk.asc"
  awk 'NR <= 6 { print; next } { s = ""; for (i = 1; i <= NF; i++) s = s " " (i % 2 ? 0.125 : 0.5); print s }' "$dir/dem.asc" > "$dir/al.asc"
  cp "$dir/dem.prj" "$dir/lk.prj"; cp "$dir/dem.prj" "$dir/al.prj"
  gt -ot Float32 -co COMPRESS=LZW -co TILED=YES -co BLOCKXSIZE=16 -co BLOCKYSIZE=16 "$dir/lk.asc" "$dir/lk.tif"
  gt -ot Float32 -co COMPRESS=DEFLATE -co PREDICTOR=3 "$dir/al.asc" "$dir/al.tif"
  run "solar, ASC maps" solar "$dir/dem.asc" --day 2026-06-21 --dirs 8 --linke-map "$dir/lk.asc" --albedo-map "$dir/al.asc" -o "$dir/sm_asc.tif" &&
    run "solar, GDAL's GeoTIFF maps" solar "$dir/dem.asc" --day 2026-06-21 --dirs 8 --linke-map "$dir/lk.tif" --albedo-map "$dir/al.tif" -o "$dir/sm_tif.tif" &&
    same "solar: GDAL's GeoTIFF Linke and albedo maps = the ASC maps" "$dir/sm_asc.tif" "$dir/sm_tif.tif"
else
  echo "SKIP gdal: gdal_translate/gdalinfo not installed"
fi

rm -rf "$dir"
echo "raster: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
