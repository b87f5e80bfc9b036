// atonlab: the command line. Subcommands are added as their issues land.
#include <cstdio>
int main() { std::puts("atonlab " ATONLAB_VERSION); return 0; }
