// atmos: MPI for the command-line tool (issue 36). `mpirun -np N atmos render ...` spreads the
// passes of a Monte Carlo render over the N ranks (rank r renders shard r + 1 of N,
// render/shards.h); rank 0 gathers the passes, merges them in pass order and
// writes the image one process would have written, byte for byte.
//
// Built with MPI when CMake finds it (ATMOS_MPI=AUTO|ON|OFF; ATMOS_HAVE_MPI),
// and only into the `atmos` executable (CMakeLists.txt leaves this file's .cpp
// out of the library: the library, tests and Python module never link MPI).
// MPI is started only when an MPI launcher (mpirun, mpiexec, srun) started the
// process, so a plain `atmos ...` never touches it; a build without MPI that
// an MPI launcher starts with more than one rank refuses to run (every rank
// would render the whole image and write the same file).
#pragma once

#include <vector>

#include "atmos/model.h"
#include "render/shards.h"

namespace atmos {

struct MpiWorld {
    int rank = 0;
    int size = 1;
};

// MPI for the process's life (MPI_Init when launched by MPI, MPI_Finalize at
// the end); Abort(status) ends every rank (MPI_Abort) after a failure on one,
// so that no rank waits for a failed one.
class MpiSession {
  public:
    MpiSession(int* argc, char*** argv);
    ~MpiSession();
    MpiSession(const MpiSession&) = delete;
    MpiSession& operator=(const MpiSession&) = delete;
    void Abort(int status);

  private:
    bool started_ = false;
};

// This process's rank and the number of ranks (0 and 1 without MPI).
const MpiWorld& World();

// Every rank calls it with its shard (rank r: shard r of World().size): at
// rank 0, every rank's shard in rank order (its own first); elsewhere, empty.
std::vector<MonteCarloShard> GatherShards(MonteCarloShard local);

}  // namespace atmos
