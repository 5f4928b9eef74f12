// atmos: MPI for the command-line tool (see mpi_world.h).
#include "harness/mpi_world.h"

#include <cstdint>
#include <cstdlib>
#include <string>
#include <utility>

#include "atmos/error.h"

#ifdef ATMOS_HAVE_MPI
#include <mpi.h>
#endif

namespace atmos {

namespace {

MpiWorld g_world;

// The number of ranks an MPI launcher gave this process (Open MPI, MPICH or
// Slurm's PMI/PMIx), 0 when none started it.
int LauncherSize() {
    for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MPI_LOCALNRANKS"}) {
        if (const char* v = std::getenv(name)) return std::atoi(v);
    }
    if (std::getenv("PMIX_RANK") || std::getenv("OMPI_COMM_WORLD_RANK")) return 1;
    return 0;
}

}  // namespace

const MpiWorld& World() { return g_world; }

#ifdef ATMOS_HAVE_MPI

namespace {

// Open MPI's handles are macros with C casts: kept in this one place.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wold-style-cast"
MPI_Comm CommWorld() { return MPI_COMM_WORLD; }
MPI_Datatype Int64Type() { return MPI_INT64_T; }
MPI_Datatype FloatType() { return MPI_FLOAT; }
MPI_Datatype CharType() { return MPI_CHAR; }
MPI_Status* IgnoreStatus() { return MPI_STATUS_IGNORE; }
#pragma GCC diagnostic pop

void Check(int code, const char* what) {
    if (code != MPI_SUCCESS) Fail("MPI: ", what, " failed (error ", code, ")");
}

void SendInts(const std::vector<int64_t>& v, int tag) {
    Check(MPI_Send(v.data(), static_cast<int>(v.size()), Int64Type(), 0, tag, CommWorld()), "send");
}

std::vector<int64_t> ReceiveInts(size_t count, int from, int tag) {
    std::vector<int64_t> v(count);
    Check(MPI_Recv(v.data(), static_cast<int>(count), Int64Type(), from, tag, CommWorld(),
                   IgnoreStatus()),
          "receive");
    return v;
}

}  // namespace

MpiSession::MpiSession(int* argc, char*** argv) {
    if (LauncherSize() == 0) return;
    if (MPI_Init(argc, argv) != MPI_SUCCESS) return;
    started_ = true;
    MPI_Comm_rank(CommWorld(), &g_world.rank);
    MPI_Comm_size(CommWorld(), &g_world.size);
}

MpiSession::~MpiSession() {
    if (started_) MPI_Finalize();
}

void MpiSession::Abort(int status) {
    if (started_ && g_world.size > 1) MPI_Abort(CommWorld(), status);
}

std::vector<MonteCarloShard> GatherShards(MonteCarloShard local) {
    std::vector<MonteCarloShard> all;
    if (g_world.size == 1) {
        all.push_back(std::move(local));
        return all;
    }
    const size_t n = static_cast<size_t>(local.width) * static_cast<size_t>(local.height) * 3;
    if (g_world.rank != 0) {
        // The fingerprint's length, the shard's sizes and pass count; the
        // fingerprint; each pass's index, samples and mean.
        SendInts(
            {static_cast<int64_t>(local.fingerprint.size()), local.index, local.count, local.passes,
             local.width, local.height, static_cast<int64_t>(local.pass_images.size())},
            1);
        Check(MPI_Send(local.fingerprint.data(), static_cast<int>(local.fingerprint.size()),
                       CharType(), 0, 2, CommWorld()),
              "send");
        for (const MonteCarloPassImage& p : local.pass_images) {
            SendInts({p.index, p.samples}, 3);
            Check(MPI_Send(p.mean.data(), static_cast<int>(n), FloatType(), 0, 4, CommWorld()),
                  "send");
        }
        return all;
    }
    all.push_back(std::move(local));
    for (int r = 1; r < g_world.size; ++r) {
        const std::vector<int64_t> head = ReceiveInts(7, r, 1);
        MonteCarloShard s;
        s.fingerprint.resize(static_cast<size_t>(head[0]));
        Check(MPI_Recv(s.fingerprint.data(), static_cast<int>(head[0]), CharType(), r, 2,
                       CommWorld(), IgnoreStatus()),
              "receive");
        s.index = head[1];
        s.count = head[2];
        s.passes = head[3];
        s.width = static_cast<int>(head[4]);
        s.height = static_cast<int>(head[5]);
        const size_t m = static_cast<size_t>(s.width) * static_cast<size_t>(s.height) * 3;
        for (int64_t i = 0; i < head[6]; ++i) {
            const std::vector<int64_t> pass = ReceiveInts(2, r, 3);
            MonteCarloPassImage p;
            p.index = pass[0];
            p.samples = pass[1];
            p.mean.Resize(s.width, s.height);
            Check(MPI_Recv(p.mean.data(), static_cast<int>(m), FloatType(), r, 4, CommWorld(),
                           IgnoreStatus()),
                  "receive");
            s.pass_images.push_back(std::move(p));
        }
        all.push_back(std::move(s));
    }
    return all;
}

#else  // no MPI in this build

MpiSession::MpiSession(int*, char***) {
    if (LauncherSize() > 1) {
        Fail(
            "this atmos was built without MPI (CMake found no MPI; ATMOS_MPI): under mpirun "
            "every rank would render the whole image; run it without mpirun, or split the "
            "render with --shard K/N and `atmos merge`");
    }
}

MpiSession::~MpiSession() = default;

void MpiSession::Abort(int) {}

std::vector<MonteCarloShard> GatherShards(MonteCarloShard local) {
    std::vector<MonteCarloShard> all;
    all.push_back(std::move(local));
    return all;
}

#endif

}  // namespace atmos
