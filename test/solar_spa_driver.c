/* solar_spa_driver.c - hfvis's side of test/solar_ephem.sh: hfvis_spa without refraction for
 * each input line "YEAR MONTH DAY HOUR MINUTE SECOND LAT LON ELEVATION DELTA_T" (UTC, degrees
 * east positive, metres, seconds TT - UT), printing "ZENITH AZIMUTH" in degrees (azimuth from
 * north toward east), or "error" for a line hfvis_spa refuses.
 * usage: solar_spa_driver < instants.txt */
#include "../hfvis.h"

#include <stdio.h>
#include <string.h>

#define PI 3.14159265358979323846

int main(void)
{
    char line[512];
    while (fgets(line, sizeof line, stdin)) {
        hfvis_spa_input in;
        hfvis_spa_result r;
        double lat, lon;
        memset(&in, 0, sizeof in);
        if (sscanf(line, "%d %d %d %d %d %lf %lf %lf %lf %lf", &in.year, &in.month, &in.day, &in.hour,
                   &in.minute, &in.second, &lat, &lon, &in.elevation_m, &in.delta_t) != 10)
            continue;
        in.latitude_rad = lat * (PI / 180.0);
        in.longitude_rad = lon * (PI / 180.0);
        if (hfvis_spa(&in, &r) != HFVIS_OK) printf("error\n");
        else printf("%.9f %.9f\n", r.zenith * (180.0 / PI), r.azimuth * (180.0 / PI));
    }
    return 0;
}
