#include "frostmpm/linalg/mpi_session.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string>

#include <mpi.h>

#include "frostmpm/config/input_error.hpp"

namespace frostmpm {
namespace {

bool mpi_initialized() {
  int flag = 0;
  MPI_Initialized(&flag);
  return flag != 0;
}

bool mpi_finalized() {
  int flag = 0;
  MPI_Finalized(&flag);
  return flag != 0;
}

/// Returns true when this call initialized MPI.
bool init_mpi_if_needed(int* argc, char*** argv) {
  if (mpi_finalized()) {
    throw std::runtime_error("MPI has already been finalized; it cannot be initialized again");
  }
  if (mpi_initialized()) return false;
  int provided = 0;
  if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
    throw std::runtime_error("MPI_Init_thread failed");
  }
  return true;
}

void finalize_mpi_if_active() {
  if (mpi_initialized() && !mpi_finalized()) MPI_Finalize();
}

/// Function-local static owner used by ensure_mpi_initialized(): finalizes at exit only
/// what it initialized.
struct LazyMpi {
  bool owns = false;
  LazyMpi() : owns(init_mpi_if_needed(nullptr, nullptr)) {}
  ~LazyMpi() {
    if (owns) finalize_mpi_if_active();
  }
  LazyMpi(const LazyMpi&) = delete;
  LazyMpi& operator=(const LazyMpi&) = delete;
};

}  // namespace

MpiSession::MpiSession() : owns_mpi_(init_mpi_if_needed(nullptr, nullptr)) {}

MpiSession::MpiSession(int& argc, char**& argv) : owns_mpi_(init_mpi_if_needed(&argc, &argv)) {}

MpiSession::~MpiSession() {
  if (owns_mpi_) finalize_mpi_if_active();
}

int MpiSession::rank() const {
  int rank = 0;
  if (mpi_is_active()) MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  return rank;
}

int MpiSession::size() const {
  int size = 1;
  if (mpi_is_active()) MPI_Comm_size(MPI_COMM_WORLD, &size);
  return size;
}

void ensure_mpi_initialized() {
  if (mpi_finalized()) {
    throw std::runtime_error("MPI has already been finalized; it cannot be initialized again");
  }
  static LazyMpi lazy;  // initializes on first use (thread-safe); finalizes at exit if it owns MPI
  // Once: a launcher the environment check in main() did not know shows in the world's size.
  static const bool one_rank = [] {
    refuse_multiple_ranks();
    return true;
  }();
  (void)lazy;
  (void)one_rank;
}

int launched_ranks() {
  // Open MPI, PMI (MPICH's Hydra, Intel MPI), PMIx, MVAPICH.
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE", "MV2_COMM_WORLD_SIZE"})
    if (const char* value = std::getenv(name)) {
      const int ranks = std::atoi(value);
      if (ranks > 0) return ranks;
    }
  if (mpi_is_active()) {
    int size = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    return size;
  }
  return 1;
}

void refuse_multiple_ranks() {
  const int ranks = launched_ranks();
  if (ranks <= 1) return;
  throw InputError("frostmpm runs on one MPI rank (this launch has " + std::to_string(ranks) +
                   "; each would run the whole problem into the same output folder): run it without "
                   "mpirun, and use --threads N for parallel loops");
}

std::string mpi_library_version() {
  char text[MPI_MAX_LIBRARY_VERSION_STRING] = {};
  int length = 0;
  MPI_Get_library_version(text, &length);  // allowed before MPI_Init
  std::string version(text, static_cast<std::size_t>(length > 0 ? length : 0));
  const auto end = version.find_first_of(",\n");
  return version.substr(0, end);
}

bool mpi_is_active() { return mpi_initialized() && !mpi_finalized(); }

}  // namespace frostmpm
