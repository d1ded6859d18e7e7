#include "hfvis.h"
#include "test.h"
TEST(smoke) { CHECK(1); }
int main(int argc, char **argv) { TEST_INIT(argc, argv); RUN(smoke); return TEST_DONE(); }
