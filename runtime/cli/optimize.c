/* placeholder replaced below */
#include "cli/commands.h"
int swim_cmd_optimize(int argc, char **argv) { (void)argc; (void)argv; return 2; }
