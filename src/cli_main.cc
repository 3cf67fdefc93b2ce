// The imusysid command-line tool: dispatches to subcommands.
#include <cstdio>
#include <cstring>
#include <string>

int main(int argc, char** /*argv*/) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: imusysid <command> [flags]\n");
    return 2;
  }
  return 0;
}
