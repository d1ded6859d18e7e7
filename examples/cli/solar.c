/* solar.c - `hfvis solar`: clear-sky irradiation (or irradiance) over the exact horizons
 * (hfvis_solar_irradiation; docs/solar.md): the dates and times, the Linke and albedo inputs, the
 * site from the raster's Transverse Mercator CRS (UTM and others, by the inverse projection) or
 * --latitude/--longitude, and the extra outputs. May call: progress.c, flags.c (numbers),
 * sweeps.c (cli_load_map), write.c (cli_save). */

#define CLI_SOLAR_MAX_DAYS 36600 /* hfvis_solar_irradiation's limit: a century */
#define CLI_SOLAR_MAX_DIRS 4096  /* hfvis_solar_options.directions: 1..4096 (hfvis.h) */

/* "YYYY-MM-DD" into y, m, d: a four-digit year (-YYYY before the year 0, astronomical
 * numbering: 0000 is 1 BC) within SPA's years -2000..6000, two-digit month and day (the library
 * checks that the date exists). */
static int cli_solar_date(const char *f, const char *v, int *y, int *m, int *d)
{
    const char *p = v + (v[0] == '-');
    int k;
    for (k = 0; k < 10; k++) /* DDDD-DD-DD */
        if (k == 4 || k == 7 ? p[k] != '-' : !isdigit((unsigned char)p[k])) break;
    if (k < 10 || p[10] != '\0')
        return cli_error(CLI_EXIT_USAGE, f, "expected a date YYYY-MM-DD (a four-digit year, -YYYY before the "
                         "year 0), got '%s'", v);
    *y = ((p[0] - '0') * 1000 + (p[1] - '0') * 100 + (p[2] - '0') * 10 + (p[3] - '0')) * (p == v ? 1 : -1);
    *m = (p[5] - '0') * 10 + (p[6] - '0');
    *d = (p[8] - '0') * 10 + (p[9] - '0');
    if (*y < -2000 || *y > 6000)
        return cli_error(CLI_EXIT_USAGE, f, "%s: the sun's position (SPA) is computed for the years -2000 to "
                         "6000 only", v);
    return 0;
}

/* Days from 0000-03-01 of the Gregorian (or, gregorian 0, the Julian) calendar to y-m-d of it. */
static long cli_solar_civil_days(int y, int m, int d, int gregorian)
{
    long yy = (long)y - (m < 3), doy = (153L * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1, era, yoe;
    if (!gregorian) { /* a leap day every 4 years */
        era = (yy >= 0 ? yy : yy - 3) / 4, yoe = yy - era * 4;
        return era * 1461 + yoe * 365 + doy;
    }
    era = (yy >= 0 ? yy : yy - 399) / 400, yoe = yy - era * 400;
    return era * 146097 + yoe * 365 + yoe / 4 - yoe / 100 + doy;
}

/* Days from 1583-01-01 of a date in the library's calendar (hfvis.c, hf_month_days and
 * hf_date_add, which step the days of a range): the Julian calendar's leap years through 1582,
 * the Gregorian calendar's from 1583, continuous across 1582-12-31 (for --start/--end
 * differences; a range across the reform's missing days is refused, cli_check_solar). */
static long cli_solar_day_number(int y, int m, int d)
{
    const int gregorian = y >= 1583;
    return cli_solar_civil_days(y, m, d, gregorian) - cli_solar_civil_days(1583, 1, 1, gregorian);
}

/* A choice flag's word: the i-th of words ("a|b|c") stores first + i in *out; else one error line
 * naming the words. */
static int sol_word(const char *f, const char *v, const char *words, int first, int *out)
{
    const char *w = words;
    int i = 0;
    size_t n = strlen(v);
    while (*w) {
        size_t len = strcspn(w, "|");
        if (len == n && !strncmp(w, v, n)) {
            *out = first + i;
            return 0;
        }
        w += len + (w[len] == '|');
        i++;
    }
    return cli_error(CLI_EXIT_USAGE, f, "expected one of %s, got '%s'", words, v);
}

/* Exactly n numbers separated by commas (cli_parse_real each) into out: 1, or 0. */
static int cli_parse_reals(const char *v, double *out, int n)
{
    int k;
    for (k = 0; k < n; k++) {
        char buf[64];
        size_t len = strcspn(v, ",");
        if (len == 0 || len >= sizeof buf) return 0;
        memcpy(buf, v, len);
        buf[len] = '\0';
        if (!cli_parse_real(buf, &out[k])) return 0;
        v += len;
        if (k < n - 1) {
            if (*v != ',') return 0;
            v++;
        }
    }
    return *v == '\0';
}

static int cli_set_solar(cli_args *a, const char *f, const char *v)
{
    if (!strcmp(f, "--day") || !strcmp(f, "--start")) {
        if (cli_solar_date(f, v, &a->sol_y, &a->sol_m, &a->sol_d)) return CLI_EXIT_USAGE;
        a->sol_has_start = 1;
        if (f[2] == 'd') a->sol_has_day = 1;
        else a->sol_has_range_start = 1;
        return 0;
    }
    if (!strcmp(f, "--end"))
        return cli_solar_date(f, v, &a->sol_ey, &a->sol_em, &a->sol_ed) ? CLI_EXIT_USAGE : (a->sol_has_end = 1, 0);
    if (!strcmp(f, "--time")) { /* HH:MM */
        int hh, mm;
        char tail;
        if (sscanf(v, "%d:%d%c", &hh, &mm, &tail) != 2 || hh < 0 || hh > 24 || mm < 0 || mm > 59 ||
            (hh == 24 && mm != 0))
            return cli_error(CLI_EXIT_USAGE, f, "expected HH:MM (00:00-24:00), got '%s'", v);
        a->sol_instant = 1;
        a->sol_hour = hh + mm / 60.0;
        return 0;
    }
    if (!strcmp(f, "--linke-monthly")) { /* 12 values, January first */
        int k, good = cli_parse_reals(v, a->sol_linke_monthly, 12);
        for (k = 0; good && k < 12; k++) good = a->sol_linke_monthly[k] > 0.0 && a->sol_linke_monthly[k] <= 10.0;
        if (!good)
            return cli_error(CLI_EXIT_USAGE, f, "expected 12 Linke factors in (0, 10], January first, "
                             "separated by commas, got '%s'", v);
        a->sol_has_linke_monthly = 1;
        return 0;
    }
    if (!strcmp(f, "--linke-map")) { a->sol_linke_map = v; return 0; }
    if (!strcmp(f, "--height-range")) { /* LO,HI: finite, LO <= HI, in IN's height unit (--zscale applied) */
        double r[2];
        if (!cli_parse_reals(v, r, 2) || !isfinite(r[0]) || !isfinite(r[1]) || r[0] > r[1])
            return cli_error(CLI_EXIT_USAGE, f, "expected LO,HI (finite heights, LO <= HI), got '%s'", v);
        a->sol_zmin = r[0];
        a->sol_zmax = r[1];
        a->sol_has_zrange = 1;
        return 0;
    }
    if (!strcmp(f, "--solar-time")) { a->sol_solar_time = 1; return 0; }
    if (!strcmp(f, "--bands")) return sol_word(f, v, "day|month", HFVIS_SOLAR_BANDS_DAY, &a->sol_bands);
    if (!strcmp(f, "--horizons"))
        return sol_word(f, v, "exact|near-far|lattice", HFVIS_SOLAR_HORIZONS_EXACT, &a->sol_horizons);
    if (!strcmp(f, "--normals"))
        return sol_word(f, v, "central|horn", HFVIS_SOLAR_NORMALS_CENTRAL, &a->sol_normals);
    if (!strcmp(f, "--beam") || !strcmp(f, "--diffuse") || !strcmp(f, "--reflected") || !strcmp(f, "--sun-hours")) {
        if (!ex_rio_format_of(v) && !cli_ends_with(v, ".pfm"))
            return cli_error(CLI_EXIT_USAGE, v, "unknown output type (use a .pfm, .tif, .asc, .bil or .flt name)");
        if (!strcmp(f, "--beam")) a->sol_out[0] = v;
        else if (!strcmp(f, "--diffuse")) a->sol_out[1] = v;
        else if (!strcmp(f, "--reflected")) a->sol_out[2] = v;
        else a->sol_out[3] = v;
        return 0;
    }
    return -1;
}

/* The days of the run: 1 for --day, --start to --end both included (cli_check_solar bounds it). */
static int cli_solar_days(const cli_args *a)
{
    if (!a->sol_has_end) return 1;
    return (int)(cli_solar_day_number(a->sol_ey, a->sol_em, a->sol_ed) -
                 cli_solar_day_number(a->sol_y, a->sol_m, a->sol_d)) + 1;
}

/* The bands of every output for the flags' dates and --bands (hfvis_solar_band_count; the site
 * does not change them), or -1 for dates the library refuses. */
static int cli_solar_band_count(const cli_args *a)
{
    hfvis_solar_input in = hfvis_solar_input_default();
    hfvis_solar_options so = hfvis_solar_options_default();
    in.year = a->sol_y, in.month = a->sol_m, in.day = a->sol_d;
    in.days = cli_solar_days(a);
    in.instant = a->sol_instant;
    in.hour = a->sol_hour;
    so.bands = (hfvis_solar_bands)a->sol_bands;
    return hfvis_solar_band_count(&in, &so);
}

/* The combinations (after every flag is read): the command row's check (main.c). */
static int cli_check_solar(const cli_args *a)
{
    if (a->sol_has_day && a->sol_has_range_start)
        return cli_error(CLI_EXIT_USAGE, "--day", "conflicts with --start: give --day DATE, or --start DATE "
                         "--end DATE");
    if (a->sol_has_day && a->sol_has_end)
        return cli_error(CLI_EXIT_USAGE, "--end", "not with --day (one day): for a range give --start DATE --end DATE");
    if (a->sol_has_range_start && !a->sol_has_end)
        return cli_error(CLI_EXIT_USAGE, "--start", "needs --end DATE (the range's last day; one day: --day DATE)");
    if (a->sol_has_end && !a->sol_has_start)
        return cli_error(CLI_EXIT_USAGE, "--end", "needs --start DATE");
    if (!a->sol_has_start) return cli_error(CLI_EXIT_USAGE, "solar", "missing --day DATE or --start DATE --end DATE");
    if (a->has_dirs && a->dirs > CLI_SOLAR_MAX_DIRS)
        return cli_error(CLI_EXIT_USAGE, "--dirs", "solar's horizon map takes 1..%d directions, got %d",
                         CLI_SOLAR_MAX_DIRS, a->dirs);
    if (a->sol_has_linke + a->sol_has_linke_monthly + (a->sol_linke_map != NULL) > 1)
        return cli_error(CLI_EXIT_USAGE, a->sol_linke_map ? "--linke-map" : "--linke-monthly", "conflicts with %s: "
                         "give one of --linke, --linke-monthly and --linke-map",
                         a->sol_has_linke ? "--linke" : "--linke-monthly");
    if (a->has_albedo && a->albedo_map)
        return cli_error(CLI_EXIT_USAGE, "--albedo-map", "conflicts with --albedo: give one of them");
    { /* dates that exist (the library's calendar: Julian through 1582-10-04, Gregorian from
         1582-10-15) */
        hfvis_solar_input in = hfvis_solar_input_default();
        int k;
        for (k = 0; k < 1 + a->sol_has_end; k++) {
            int y = k ? a->sol_ey : a->sol_y, m = k ? a->sol_em : a->sol_m, d = k ? a->sol_ed : a->sol_d;
            in.year = y, in.month = m, in.day = d;
            if (hfvis_solar_band_count(&in, NULL) < 0)
                return cli_error(CLI_EXIT_USAGE, k ? "--end" : a->sol_has_day ? "--day" : "--start",
                                 "%04d-%02d-%02d is not a date of the calendar%s", y, m, d,
                                 y == 1582 && m == 10 && d > 4 && d < 15
                                     ? " (the Gregorian reform followed 1582-10-04 with 1582-10-15)"
                                 : y <= 1582 ? " (Julian before 1582-10-15)" : "");
        }
    }
    if (a->sol_has_end) {
        long d = cli_solar_day_number(a->sol_ey, a->sol_em, a->sol_ed) - cli_solar_day_number(a->sol_y, a->sol_m, a->sol_d);
        long s = (long)a->sol_y * 10000 + a->sol_m * 100 + a->sol_d;
        long e = (long)a->sol_ey * 10000 + a->sol_em * 100 + a->sol_ed;
        if (a->sol_instant) return cli_error(CLI_EXIT_USAGE, "--time", "is an instant: give --day, not --start/--end");
        if (d < 0 || d >= CLI_SOLAR_MAX_DAYS)
            return cli_error(CLI_EXIT_USAGE, "--end", "expected a date from --start to %d days after it",
                             CLI_SOLAR_MAX_DAYS - 1);
        if (s <= 15821004L && e >= 15821015L) /* the library steps a range day by day without the gap */
            return cli_error(CLI_EXIT_USAGE, "--end", "a range across the Gregorian reform (1582-10-04 was "
                             "followed by 1582-10-15) is not stepped right: end it by 1582-10-04 or start "
                             "it from 1582-10-15");
    }
    if (a->sol_solar_time && a->sol_has_offset)
        return cli_error(CLI_EXIT_USAGE, "--solar-time", "times are local solar time: no --utc-offset");
    if (a->has_albedo && !(a->albedo >= 0.0 && a->albedo <= 1.0))
        return cli_error(CLI_EXIT_USAGE, "--albedo", "expected an albedo in [0, 1], got %g", a->albedo);
    if (a->sol_has_lat != a->sol_has_lon)
        return cli_error(CLI_EXIT_USAGE, a->sol_has_lat ? "--latitude" : "--longitude",
                         "give both --latitude and --longitude");
    if (a->out_pgm || a->out_partial)
        return cli_error(CLI_EXIT_USAGE, a->out, "solar writes .pfm, .tif, .asc, .bil or .flt");
    { /* an ASCII grid holds one band: refused before the run, not after it */
        const char *outs[5];
        int k, bands = cli_solar_band_count(a);
        outs[0] = a->out, outs[1] = a->sol_out[0], outs[2] = a->sol_out[1], outs[3] = a->sol_out[2];
        outs[4] = a->sol_out[3];
        for (k = 0; k < 5; k++)
            if (bands > 1 && outs[k] && ex_rio_format_of(outs[k]) == EX_RIO_ASC)
                return cli_error(CLI_EXIT_USAGE, outs[k], "an ASCII grid holds one band; --bands %s gives %d: "
                                 "write .tif, .bil, .flt or .pfm", a->sol_bands == HFVIS_SOLAR_BANDS_DAY ? "day"
                                 : "month", bands);
    }
    return 0;
}

/* Transverse Mercator, inverse (Snyder 1987, USGS PP 1395, Eq. 8-12 and 3-21, 7-19 ... 7-26 for
 * the ellipsoid): map (x, y) in metres to latitude and longitude in degrees. */
typedef struct cli_tm { double a, f, k0, lon0, lat0, x0, y0; } cli_tm;

static double cli_tm_meridian(double a, double e2, double phi)
{
    double e4 = e2 * e2, e6 = e4 * e2;
    return a * ((1.0 - e2 / 4.0 - 3.0 * e4 / 64.0 - 5.0 * e6 / 256.0) * phi -
                (3.0 * e2 / 8.0 + 3.0 * e4 / 32.0 + 45.0 * e6 / 1024.0) * sin(2.0 * phi) +
                (15.0 * e4 / 256.0 + 45.0 * e6 / 1024.0) * sin(4.0 * phi) - (35.0 * e6 / 3072.0) * sin(6.0 * phi));
}

static void cli_tm_inverse(const cli_tm *t, double x, double y, double *lat, double *lon)
{
    double e2 = t->f * (2.0 - t->f), ep2 = e2 / (1.0 - e2), r = CLI_PI / 180.0;
    double M = cli_tm_meridian(t->a, e2, t->lat0 * r) + (y - t->y0) / t->k0;
    double mu = M / (t->a * (1.0 - e2 / 4.0 - 3.0 * e2 * e2 / 64.0 - 5.0 * e2 * e2 * e2 / 256.0));
    double e1 = (1.0 - sqrt(1.0 - e2)) / (1.0 + sqrt(1.0 - e2));
    double p1 = mu + (1.5 * e1 - 27.0 * e1 * e1 * e1 / 32.0) * sin(2.0 * mu) +
                (21.0 * e1 * e1 / 16.0 - 55.0 * e1 * e1 * e1 * e1 / 32.0) * sin(4.0 * mu) +
                (151.0 * e1 * e1 * e1 / 96.0) * sin(6.0 * mu) + (1097.0 * e1 * e1 * e1 * e1 / 512.0) * sin(8.0 * mu);
    double c1 = ep2 * cos(p1) * cos(p1), t1 = tan(p1) * tan(p1), s = sin(p1);
    double n1 = t->a / sqrt(1.0 - e2 * s * s), r1 = t->a * (1.0 - e2) / pow(1.0 - e2 * s * s, 1.5);
    double D = (x - t->x0) / (n1 * t->k0), D2 = D * D;
    *lat = (p1 - (n1 * tan(p1) / r1) *
                     (D2 / 2.0 - (5.0 + 3.0 * t1 + 10.0 * c1 - 4.0 * c1 * c1 - 9.0 * ep2) * D2 * D2 / 24.0 +
                      (61.0 + 90.0 * t1 + 298.0 * c1 + 45.0 * t1 * t1 - 252.0 * ep2 - 3.0 * c1 * c1) * D2 * D2 * D2 / 720.0)) / r;
    *lon = t->lon0 + (D - (1.0 + 2.0 * t1 + c1) * D2 * D / 6.0 +
                      (5.0 - 2.0 * c1 + 28.0 * t1 - 3.0 * c1 * c1 + 8.0 * ep2 + 24.0 * t1 * t1) * D2 * D2 * D / 120.0) /
                         cos(p1) / r;
}

/* A WKT PARAMETER["name", value] (case-insensitive name); 1 if found. */
static int cli_wkt_param(const char *wkt, const char *name, double *v)
{
    const char *p = wkt;
    size_t n = strlen(name);
    while ((p = strstr(p, "PARAMETER[\"")) != NULL) {
        size_t i;
        p += 11;
        for (i = 0; i < n && p[i] && tolower((unsigned char)p[i]) == tolower((unsigned char)name[i]); i++) {}
        if (i == n && p[n] == '"') return sscanf(p + n + 1, " ,%lf", v) == 1;
    }
    return 0;
}

/* A GeoKey's value (GeoTIFF 1.1 §7.1): its SHORT, or its DOUBLE from GeoDoubleParams; 1 if the
 * raster has it. */
static int cli_geokey(const ex_georef *g, unsigned id, double *v)
{
    size_t i, n = g->n_geokeys >= 4 ? g->geokeys[3] : 0;
    for (i = 1; i <= n && 4 * i + 3 < g->n_geokeys; i++) {
        const uint16_t *k = g->geokeys + 4 * i;
        if (k[0] != id) continue;
        if (k[1] == 0 && k[2] == 1) *v = (double)k[3];
        else if (k[1] == 34736 && k[2] >= 1 && (size_t)k[3] < g->n_geodoubles) *v = g->geodoubles[k[3]];
        else return 0;
        return 1;
    }
    return 0;
}

/* The raster's Transverse Mercator, if it has one, from (in this order): a UTM EPSG code (WGS 84
 * 326zz north and 327zz south, ETRS89 258zz, NAD83 269zz, NAD83(2011) 6330-6348 for zones 1-19
 * north); the GeoTIFF's own projection keys (ProjCoordTransGeoKey 1, Transverse Mercator, with
 * its natural origin, scale and false easting and northing); or a WKT (.prj, GeoTIFF citation)
 * naming Transverse_Mercator with its central meridian, scale factor and false easting and
 * northing. A CRS that names Transverse Mercator without its parameters (a GeoTIFF holding only
 * an EPSG code and its name) is not guessed at: 0, as for any other CRS. */
static int cli_solar_tm(const ex_georef *g, cli_tm *t)
{
    const char *wkt = g->prj ? g->prj : g->geoascii;
    int zone = 0, south = 0;
    double v, k0, lon0, x0, y0;
    t->a = 6378137.0;
    t->f = 1.0 / 298.257223563; /* WGS 84 (GRS 80 differs by 1e-10 in f) */
    t->lat0 = 0.0;
    if (g->epsg > 32600 && g->epsg <= 32660) zone = g->epsg - 32600;
    else if (g->epsg > 32700 && g->epsg <= 32760) zone = g->epsg - 32700, south = 1;
    else if (g->epsg >= 25828 && g->epsg <= 25838) zone = g->epsg - 25800;
    else if (g->epsg >= 26901 && g->epsg <= 26923) zone = g->epsg - 26900;
    else if (g->epsg >= 6330 && g->epsg <= 6348) zone = g->epsg - 6329;
    if (zone) {
        t->k0 = 0.9996;
        t->lon0 = -183.0 + 6.0 * zone;
        t->x0 = 500000.0;
        t->y0 = south ? 10000000.0 : 0.0;
        return 1;
    }
    if (cli_geokey(g, 3075, &v) && v == 1.0 && /* ProjCoordTransGeoKey: CT_TransverseMercator */
        (cli_geokey(g, 3080, &lon0) || cli_geokey(g, 3088, &lon0)) && /* natural origin or centre */
        (cli_geokey(g, 3092, &k0) || cli_geokey(g, 3093, &k0)) && cli_geokey(g, 3082, &x0) &&
        cli_geokey(g, 3083, &y0)) {
        double a, inv_f;
        t->k0 = k0;
        t->lon0 = lon0;
        t->x0 = x0;
        t->y0 = y0;
        if (cli_geokey(g, 3081, &v) || cli_geokey(g, 3089, &v)) t->lat0 = v;
        if (cli_geokey(g, 2057, &a) && cli_geokey(g, 2059, &inv_f) && a > 6e6 && a < 7e6 && inv_f > 250.0) {
            t->a = a;
            t->f = 1.0 / inv_f;
        }
        return k0 > 0.0 && isfinite(lon0 + x0 + y0 + t->lat0);
    }
    if (wkt && (strstr(wkt, "Transverse_Mercator") || strstr(wkt, "TRANSVERSE_MERCATOR") ||
                strstr(wkt, "Transverse Mercator")) &&
        cli_wkt_param(wkt, "scale_factor", &k0) && cli_wkt_param(wkt, "central_meridian", &lon0) &&
        cli_wkt_param(wkt, "false_easting", &x0) && cli_wkt_param(wkt, "false_northing", &y0) && k0 > 0.0) {
        const char *sp = strstr(wkt, "SPHEROID[\"");
        t->k0 = k0;
        t->lon0 = lon0;
        t->x0 = x0;
        t->y0 = y0;
        t->lat0 = cli_wkt_param(wkt, "latitude_of_origin", &v) ? v : 0.0;
        if (sp && (sp = strchr(sp + 10, '"')) != NULL) {
            double a, inv_f;
            if (sscanf(sp + 1, " ,%lf ,%lf", &a, &inv_f) == 2 && a > 6e6 && a < 7e6 && inv_f > 250.0) {
                t->a = a;
                t->f = 1.0 / inv_f;
            }
        }
        return 1;
    }
    return 0;
}

/* Per-cell sites (hfvis_solar_input.site): raster cell (x, y)'s centre placed by the raster's
 * own georeference (a piece's is shifted to its window: not that one, whose sums round
 * otherwise) and inverse-projected; the grid's cells cached, the others (the library's blocks
 * and their frames are cut from the whole raster) computed when asked, by the same function. */
typedef struct cli_solar_sites {
    cli_tm tm;
    double gt[6];
    int gx0, gy0, gw, gh;  /* the grid's cells within the raster */
    double *lat, *lon;     /* the grid's sites, radians */
} cli_solar_sites;

/* Raster cell (x, y)'s site in degrees, the longitude in [-180, 180]; 0 where it maps nowhere. */
static int cli_solar_site_deg(const cli_solar_sites *s, int x, int y, double *la, double *lo)
{
    double px = (double)x + 0.5, py = (double)y + 0.5;
    cli_tm_inverse(&s->tm, s->gt[0] + s->gt[1] * px + s->gt[2] * py, s->gt[3] + s->gt[4] * px + s->gt[5] * py,
                   la, lo);
    if (!(fabs(*la) <= 90.0) || !(fabs(*lo) <= 540.0)) return 0;
    while (*lo > 180.0) *lo -= 360.0;
    while (*lo < -180.0) *lo += 360.0;
    return 1;
}

/* The library's site function: radians; NaN where the cell maps nowhere (the library refuses). */
static void cli_solar_site(void *user, int x, int y, double *lat, double *lon)
{
    const cli_solar_sites *s = (const cli_solar_sites *)user;
    double la, lo;
    if (x >= s->gx0 && x < s->gx0 + s->gw && y >= s->gy0 && y < s->gy0 + s->gh) {
        size_t i = (size_t)(y - s->gy0) * (size_t)s->gw + (size_t)(x - s->gx0);
        *lat = s->lat[i];
        *lon = s->lon[i];
        return;
    }
    if (!cli_solar_site_deg(s, x, y, &la, &lo)) {
        *lat = *lon = (double)NAN;
        return;
    }
    *lat = la * (CLI_PI / 180.0);
    *lon = lo * (CLI_PI / 180.0);
}

/* With --max-distance (whole runs and windows alike): the whole raster's lowest and highest
 * finite heights as cli_load_heights makes them (--band, --nodata, --zscale), read a strip of
 * rows at a time, for the pressure nodes (hfvis_solar_options.height_min/max) that a window's
 * grid must share with the whole run. 0, 0 when there is none. */
static int cli_solar_height_range(const cli_args *a, double *lo, double *hi)
{
    ex_rio_reader r;
    float *strip, nodata = (float)a->nodata, zscale = (float)a->zscale, zmin = HUGE_VALF, zmax = -HUGE_VALF;
    int y, rows, rc = 0;
    *lo = *hi = 0.0;
    if (cli_open_raster(&r, a->in) != 0) {
        rc = cli_error(CLI_EXIT_ERROR, a->in, "%s", r.err);
        ex_rio_close(&r);
        return rc;
    }
    rows = r.width < 65536 ? 65536 / r.width : 1;
    if (r.format == EX_RIO_TIFF && r.chunk_h > 0 && r.chunk_h <= 4096) /* whole strips or tile rows: */
        rows = (int)(((uint32_t)rows + r.chunk_h - 1) / r.chunk_h * r.chunk_h); /* each decoded once */
    if (!(strip = cli_alloc((size_t)r.width, (size_t)rows, 1))) {
        ex_rio_close(&r);
        return cli_status(a->in, HFVIS_ERR_OUT_OF_MEMORY, 0);
    }
    r.nodata_to_nan = 1;
    for (y = 0; y < r.height && rc == 0; y += rows) {
        int n = r.height - y < rows ? r.height - y : rows, i;
        if (ex_rio_read(&r, a->band ? a->band - 1 : 0, 0, y, r.width, n, strip, r.width) != 0) {
            rc = cli_error(CLI_EXIT_ERROR, a->in, "%s", r.err);
            break;
        }
        for (i = 0; i < n * r.width; i++) {
            float v = strip[i], z;
            if ((a->has_nodata && v == nodata) || !isfinite(v)) continue; /* holes */
            z = v * zscale;
            if (!isfinite(z)) continue; /* the load refuses it where it is read */
            if (z < zmin) zmin = z;
            if (z > zmax) zmax = z;
        }
    }
    free(strip);
    ex_rio_close(&r);
    if (rc == 0 && zmin <= zmax) {
        *lo = (double)zmin;
        *hi = (double)zmax;
    }
    return rc;
}

/* --threads N: the time integration by bands of rows (hfvis_solar_options.row_begin/end), one
 * per thread, each writing its own rows of the outputs, bit for bit the one-thread run's; a
 * window's bands cut its own rows (the receiver rectangle's). */
typedef struct cli_solar_split {
    const hfvis_grid *grid;
    const hfvis_solar_input *in;
    const hfvis_solar_options *so;
    const hfvis_solar_output *out;
    int parts, row0, rows;
} cli_solar_split;

static hfvis_status cli_solar_unit(cli_split *sp, int u, int thread, hfvis_sweep_options *o)
{
    cli_solar_split *j = (cli_solar_split *)sp->ctx;
    hfvis_solar_options so = *j->so;
    (void)thread;
    so.sweep = o;
    so.row_begin = j->row0 + (int)((long long)j->rows * u / j->parts);
    so.row_end = j->row0 + (int)((long long)j->rows * (u + 1) / j->parts);
    if (so.row_begin >= so.row_end) return HFVIS_OK;
    return hfvis_solar_irradiation(j->grid, j->in, &so, j->out);
}

static hfvis_status cli_threaded_solar(const hfvis_grid *grid, const hfvis_solar_input *in,
                                       const hfvis_solar_options *so, const hfvis_solar_output *out,
                                       int threads)
{
    cli_solar_split j;
    cli_split sp;
    const hfvis_sweep_options *o = so->sweep;
    j.row0 = o && o->receiver_height ? o->receiver_y : 0;
    j.rows = o && o->receiver_height ? o->receiver_height : grid->height;
    if (threads <= 1 || j.rows < 2 || so->reflected == HFVIS_SOLAR_REFLECTED_TERRAIN)
        return hfvis_solar_irradiation(grid, in, so, out);
    memset(&sp, 0, sizeof sp);
    j.grid = grid;
    j.in = in;
    j.so = so;
    j.out = out;
    j.parts = threads < j.rows ? threads : j.rows;
    sp.units = j.parts;
    sp.threads = j.parts;
    sp.unit = cli_solar_unit;
    sp.ctx = &j;
    sp.opts = so->sweep;
    sp.total = j.parts;
    return cli_split_run(&sp);
}

/* An output's unit: W/m^2 of an instant, Wh/m^2 of a period, hours of direct sun (none for an
 * instant's sun-hours output, its visible fraction of the sun). */
static const char *cli_solar_unit_of(int instant, int sun_hours)
{
    return sun_hours ? (instant ? NULL : "h") : instant ? "W/m^2" : "Wh/m^2";
}

/* Each band's description in a GeoTIFF (GDAL_METADATA: gdalinfo and QGIS show it): with
 * --bands day its date, "YYYY-MM-DD", with --bands month its month, "YYYY-MM", stepped from the
 * first day in the library's calendar (Julian leap years through 1582); one band: none (NULL).
 * *names holds the text, *ptrs the pointers cli_output takes; 0, or 1 when memory runs out. */
static int cli_solar_band_names(const cli_args *a, int bands, char (**names)[16], const char ***ptrs)
{
    int y = a->sol_y, m = a->sol_m, d = a->sol_d, k;
    *names = NULL;
    *ptrs = NULL;
    if (bands < 2) return 0;
    *names = (char (*)[16])calloc((size_t)bands, sizeof **names);
    *ptrs = (const char **)calloc((size_t)bands, sizeof **ptrs);
    if (!*names || !*ptrs) return 1;
    for (k = 0; k < bands; k++) {
        int days = (int)(cli_solar_day_number(m == 12 ? y + 1 : y, m == 12 ? 1 : m + 1, 1) -
                         cli_solar_day_number(y, m, 1)); /* the month's, in the range's own count */
        if (a->sol_bands == HFVIS_SOLAR_BANDS_DAY) {
            snprintf((*names)[k], sizeof **names, "%04d-%02d-%02d", y, m, d);
            if (++d > days) d = 1, m++;
        } else {
            snprintf((*names)[k], sizeof **names, "%04d-%02d", y, m);
            m++;
        }
        if (m > 12) m = 1, y++;
        (*ptrs)[k] = (*names)[k];
    }
    return 0;
}

/* The band descriptions and unit of one output of a --window run, from its piece tag (tiles.c:
 * solar-labels= the first day, the instant and --bands; solar-output= the output), for hfvis
 * mosaic: those of the whole run. A tag without them (an older hfvis) gives none. 0, or 1 when
 * memory runs out. */
static int cli_solar_labels_of_tag(const char *tag, int bands, char (**names)[16], const char ***ptrs,
                                   const char **unit)
{
    char v[64];
    cli_args b;
    int kind;
    *names = NULL;
    *ptrs = NULL;
    memset(&b, 0, sizeof b);
    if (!cli_tag_value(tag, "solar-labels", v, sizeof v) ||
        sscanf(v, "%d-%d-%d,%d,%d", &b.sol_y, &b.sol_m, &b.sol_d, &b.sol_instant, &kind) != 5)
        return 0;
    b.sol_bands = (hfvis_solar_bands)kind;
    *unit = cli_solar_unit_of(b.sol_instant, cli_tag_value(tag, "solar-output", v, sizeof v) && !strcmp(v, "sun-hours"));
    return cli_solar_band_names(&b, bands, names, ptrs);
}

static int cli_run_solar(const cli_args *a, const hfvis_grid *grid, hfvis_sweep_options *opts)
{
    const int w = grid->width, h = grid->height;
    hfvis_solar_input in = hfvis_solar_input_default();
    hfvis_solar_options so = hfvis_solar_options_default();
    hfvis_solar_output out;
    float *planes[5] = { NULL, NULL, NULL, NULL, NULL }, *albedo = NULL, *linke = NULL, monthly[12];
    float *hmap = NULL;
    unsigned char *need = NULL;
    char (*band_text)[16] = NULL;
    const char *paths[5], **band_names = NULL;
    char tag[CLI_PIECE_TAG_MAX];
    cli_solar_sites sites;
    hfvis_status s;
    int rc = 0, bands, j, k, ch, piece = a->run->win.active;
    double lat = a->sol_lat, lon = a->sol_lon;
    memset(&sites, 0, sizeof sites);
    if (!a->sol_has_lat) { /* every cell's site by the inverse projection of its centre */
        size_t i, n = (size_t)w * (size_t)h;
        if (!a->run->geo.has_transform || !cli_solar_tm(&a->run->geo, &sites.tm)) {
            char crs[32] = "IN's CRS";
            if (a->run->geo.epsg > 0) snprintf(crs, sizeof crs, "EPSG:%d", a->run->geo.epsg);
            return cli_error(CLI_EXIT_ERROR, "solar", "the latitude is unknown: %s is not a Transverse "
                             "Mercator hfvis can invert (UTM by EPSG 326zz, 327zz, 258zz, 269zz or "
                             "6330-6348, or its parameters in GeoTIFF keys or a WKT); give --latitude "
                             "and --longitude", crs);
        }
        sites.lat = (double *)(void *)cli_alloc(n, 2, sizeof(double) / sizeof(float)); /* 2n doubles */
        if (!sites.lat) return cli_status("solar", HFVIS_ERR_OUT_OF_MEMORY, 0);
        sites.lon = sites.lat + n;
        if (piece && !a->has_geotransform && a->run->win.has_gt) /* the raster's, not the piece's */
            memcpy(sites.gt, a->run->win.raster_gt, sizeof sites.gt);
        else
            cli_georef(a, grid->cell_size, sites.gt);
        sites.gx0 = piece ? a->run->win.gx0 : 0, sites.gy0 = piece ? a->run->win.gy0 : 0;
        sites.gw = w, sites.gh = h;
        for (i = 0; i < n; i++) {
            int x = sites.gx0 + (int)(i % (size_t)w), y = sites.gy0 + (int)(i / (size_t)w);
            double la, lo;
            if (!cli_solar_site_deg(&sites, x, y, &la, &lo)) {
                free(sites.lat);
                return cli_error(CLI_EXIT_ERROR, "solar", "cell %d, %d does not map to a latitude and "
                                 "longitude", x, y);
            }
            sites.lat[i] = la * (CLI_PI / 180.0);
            sites.lon[i] = lo * (CLI_PI / 180.0);
        }
        cli_tm_inverse(&sites.tm, sites.gt[0] + sites.gt[1] * (sites.gx0 + w / 2.0) + sites.gt[2] * (sites.gy0 + h / 2.0),
                       sites.gt[3] + sites.gt[4] * (sites.gx0 + w / 2.0) + sites.gt[5] * (sites.gy0 + h / 2.0), &lat, &lon);
        while (lon > 180.0) lon -= 360.0; /* the centre's (every cell's mapped above) */
        while (lon < -180.0) lon += 360.0;
        in.site = cli_solar_site;
        in.site_user = &sites;
    }
    if (a->progress_lines && !a->quiet)
        fprintf(stderr, "hfvis solar: site %.5f, %.5f (latitude, longitude of the grid's centre%s)\n", lat, lon,
                sites.lat ? "; each cell's own by the inverse projection" : "");
    in.latitude_rad = lat * (CLI_PI / 180.0);
    in.longitude_rad = lon * (CLI_PI / 180.0);
    in.year = a->sol_y;
    in.month = a->sol_m;
    in.day = a->sol_d;
    in.days = cli_solar_days(a);
    in.instant = a->sol_instant;
    in.hour = a->sol_hour;
    in.utc_offset_hours = a->sol_offset;
    if (a->sol_has_linke) in.linke = a->sol_linke;
    in.albedo = a->has_albedo ? a->albedo : 0.2;
    so.model = a->sol_solar_time ? HFVIS_SUN_RSUN : HFVIS_SUN_SPA;
    if (a->sol_step > 0.0) so.step_hours = a->sol_step;
    if (a->has_dirs) so.directions = a->dirs;
    if (a->has_sun_radius) so.sun_radius_rad = a->sun_radius * (CLI_PI / 180.0);
    so.bands = (hfvis_solar_bands)a->sol_bands;
    so.horizons = (hfvis_solar_horizons)a->sol_horizons;
    so.normals = (hfvis_solar_normals)a->sol_normals;
    so.sweep = opts;
    if (a->sol_has_zrange) { /* the caller's range: no pass over IN; every height read must lie in it,
                                compared as the floats the heights are (a range printed from
                                them with 9 digits holds them) */
        const float flo = (float)a->sol_zmin, fhi = (float)a->sol_zmax;
        const size_t gw = (size_t)grid->width, n = gw * (size_t)grid->height;
        const size_t x0 = a->run->win.active ? (size_t)a->run->win.gx0 : 0, y0 = a->run->win.active ? (size_t)a->run->win.gy0 : 0;
        size_t i;
        for (i = 0; i < n; i++)
            if (isfinite(grid->z[i]) && !(grid->z[i] >= flo && grid->z[i] <= fhi)) {
                rc = cli_error(CLI_EXIT_ERROR, "--height-range", "the height %.9g at column %lu, row %lu of %s lies "
                               "outside %.9g,%.9g", (double)grid->z[i], (unsigned long)(x0 + i % gw),
                               (unsigned long)(y0 + i / gw), a->in, a->sol_zmin, a->sol_zmax);
                goto done;
            }
        so.height_min = a->sol_zmin;
        so.height_max = a->sol_zmax;
    } else if (a->max_distance > 0.0 && (rc = cli_solar_height_range(a, &so.height_min, &so.height_max)) != 0) {
        goto done;
    }
    if (a->sol_has_linke_monthly) {
        for (k = 0; k < 12; k++) monthly[k] = (float)a->sol_linke_monthly[k];
        so.linke_monthly = monthly;
    }
    if (a->albedo_map) {
        if ((rc = cli_load_map(a->albedo_map, &a->run->win, grid, &albedo, &ch)) != 0) goto done;
        if (ch != 1) {
            rc = cli_error(CLI_EXIT_ERROR, a->albedo_map, "%d bands or channels: an albedo map has one", ch);
            goto done;
        }
        so.albedo_map = albedo;
    }
    if (a->sol_linke_map) {
        if ((rc = cli_load_map(a->sol_linke_map, &a->run->win, grid, &linke, &ch)) != 0) goto done;
        if (ch != 1) {
            rc = cli_error(CLI_EXIT_ERROR, a->sol_linke_map, "%d bands or channels: a Linke map has one", ch);
            goto done;
        }
    }
    so.linke_map = linke;
    bands = hfvis_solar_band_count(&in, &so);
    if (bands < 1) {
        rc = cli_error(CLI_EXIT_ERROR, "solar", "an input is out of range (latitude %g, longitude %g)", lat, lon);
        goto done;
    }
    if ((long long)bands * h > HFVIS_IMAGE_MAX_DIM) {
        rc = cli_error(CLI_EXIT_ERROR, "--bands", "%d bands of %d rows exceed %d rows", bands, h, HFVIS_IMAGE_MAX_DIM);
        goto done;
    }
    paths[0] = a->sol_out[0]; paths[1] = a->sol_out[1]; paths[2] = a->sol_out[2];
    paths[3] = a->out; paths[4] = a->sol_out[3];
    for (k = 0; k < 5; k++)
        if (paths[k] && !(planes[k] = cli_alloc((size_t)w * (size_t)h, (size_t)bands, 1))) {
            rc = cli_status("solar", HFVIS_ERR_OUT_OF_MEMORY, 0);
            goto done;
        }
    out.beam = planes[0]; out.diffuse = planes[1]; out.reflected = planes[2];
    out.global = planes[3]; out.sun_hours = planes[4];
    if (cli_run_threads(a) > 1) { /* the horizon map by directions over the threads (bit for bit),
                                     only the directions the steps read (the others stay 0, unread) */
        hfvis_sweep_options ms = hfvis_solar_map_options(&so); /* as the library's own map */
        int K = so.directions;
        if (!(hmap = cli_alloc((size_t)w * (size_t)h, (size_t)K, 1)) || !(need = (unsigned char *)malloc((size_t)K))) {
            rc = cli_status("solar", HFVIS_ERR_OUT_OF_MEMORY, 0);
            goto done;
        }
        if (hfvis_solar_map_directions(grid, &in, &so, need) != HFVIS_OK) { /* bad input: the run below names it */
            free(need);
            need = NULL;
        }
        if ((s = cli_threaded_horizon_map(grid, K, &ms, cli_run_threads(a), need, hmap)) != HFVIS_OK) {
            rc = cli_status("solar", s, 0);
            goto done;
        }
        so.horizon_map = hmap;
    }
    s = cli_threaded_solar(grid, &in, &so, &out, cli_run_threads(a));
    if (s == HFVIS_ERR_INVALID_ARGUMENT && (a->sol_linke_map || a->albedo_map)) {
        rc = cli_error(CLI_EXIT_ERROR, a->sol_linke_map ? a->sol_linke_map : a->albedo_map,
                       "a value out of range (Linke (0, 10], albedo [0, 1])");
        goto done;
    }
    if (s != HFVIS_OK) { rc = cli_status("solar", s, 0); goto done; }
    memcpy(tag, a->run->win.tag, sizeof tag);
    if (cli_solar_band_names(a, bands, &band_text, &band_names)) {
        rc = cli_status("solar", HFVIS_ERR_OUT_OF_MEMORY, 0);
        goto done;
    }
    for (j = 0; j < 5 && rc == 0; j++) { /* OUT (k = 3) last: a failing write leaves it untouched */
        static const char *const kind[5] = { "beam", "diffuse", "reflected", "global", "sun-hours" };
        static const int order[5] = { 0, 1, 2, 4, 3 };
        cli_args b = *a;
        cli_output o;
        k = order[j];
        if (!paths[k]) continue;
        b.out = paths[k];
        b.out_pgm = 0;
        b.out_raster = ex_rio_format_of(paths[k]) != 0;
        a->run->win.active = piece; /* each output a piece (cli_save_piece clears it) */
        snprintf(a->run->win.tag, sizeof a->run->win.tag, "%.*s solar-output=%s",
                 (int)(sizeof tag - 32), tag, kind[k]); /* pieces of one output only */
        o = cli_output_of(planes[k], w, h, bands, 1, 0.0, 1.0);
        o.band_names = band_names;
        o.unit = cli_solar_unit_of(a->sol_instant, k == 4);
        rc = cli_save(&b, o);
    }
done:
    free(band_text);
    free(band_names);
    for (k = 0; k < 5; k++) free(planes[k]);
    hfvis_free(NULL, albedo);
    hfvis_free(NULL, linke);
    free(sites.lat);
    free(hmap);
    free(need);
    return rc;
}
