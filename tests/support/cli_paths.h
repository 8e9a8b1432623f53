/* cli_paths.h: where the tests and the benchmark find the built commands
 * and mpirun. The Makefile passes the build's own paths; these defaults are
 * the optimised build's, for a compile by hand. */
#ifndef PD_TEST_CLI_PATHS_H
#define PD_TEST_CLI_PATHS_H

#ifndef PD_CLI_PATH
#define PD_CLI_PATH "build/opt/posedrop"
#endif
#ifndef PD_CLI_MPI_PATH
#define PD_CLI_MPI_PATH "build/opt/posedrop-mpi"
#endif
#ifndef PD_MPIRUN
#define PD_MPIRUN "mpirun"
#endif

#endif
