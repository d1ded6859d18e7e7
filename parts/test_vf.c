#include "hfvis.h"
#include "test.h"
TEST(counts) { CHECK(hfvis_visfield_position_count(32) == 4226); }
int main(int argc, char **argv) { TEST_INIT(argc, argv); RUN(counts); return TEST_DONE(); }
