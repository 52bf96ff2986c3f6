#include "cli/app.h"

int main(int argc, char** argv) { return hprt::cli::run(argc, argv); }
