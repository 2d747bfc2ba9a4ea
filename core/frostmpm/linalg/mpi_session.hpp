#pragma once
// MPI lifetime without exposing <mpi.h>: programs may hold an MpiSession in main(), and library
// code that needs MPI (the Trilinos solvers) calls ensure_mpi_initialized(), so a plain
// executable, `mpirun -np 1` and `mpirun -np N` all work without special set-up.
//
// Rule: whoever calls MPI_Init calls MPI_Finalize; nobody initializes MPI twice or finalizes
// MPI that someone else initialized.

#include <string>

namespace frostmpm {

/// RAII MPI session for a program's main(). Calls MPI_Init only if MPI is not initialized yet,
/// and MPI_Finalize on destruction only if this object called MPI_Init. MPI cannot be
/// re-initialized after MPI_Finalize, so create at most one owning session, at the top of main().
class MpiSession {
 public:
  MpiSession();                          ///< without command-line arguments
  MpiSession(int& argc, char**& argv);   ///< passes the arguments to MPI_Init
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  /// True when this object called MPI_Init (and so will call MPI_Finalize).
  bool owns_mpi() const { return owns_mpi_; }
  int rank() const;  ///< rank in MPI_COMM_WORLD
  int size() const;  ///< size of MPI_COMM_WORLD

 private:
  bool owns_mpi_ = false;
};

/// Makes sure MPI is initialized. If this call is the one that initializes it, MPI_Finalize
/// runs at program exit (after the destructors of static objects created later). Cheap and
/// safe to call repeatedly. Throws std::runtime_error if MPI has already been finalized.
void ensure_mpi_initialized();

/// True when MPI is initialized and not yet finalized.
bool mpi_is_active();

/// The number of ranks the MPI launcher started (mpirun/mpiexec of Open MPI, MPICH, Intel MPI,
/// PMIx), read from its environment without initializing MPI: 1 when not launched by one.
int launched_ranks();

/// Runs are not distributed yet: throws InputError with one line when more than one rank was
/// launched (every rank would run the whole problem into the same output folder).
void refuse_multiple_ranks();

/// The linked MPI library, e.g. "Open MPI v4.1.4" (first line of MPI_Get_library_version).
std::string mpi_library_version();

}  // namespace frostmpm
