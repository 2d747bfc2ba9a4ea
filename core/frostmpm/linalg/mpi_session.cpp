#include "frostmpm/linalg/mpi_session.hpp"

#include <stdexcept>

#include <mpi.h>

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
  (void)lazy;
}

bool mpi_is_active() { return mpi_initialized() && !mpi_finalized(); }

}  // namespace frostmpm
