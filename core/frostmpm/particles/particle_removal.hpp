#pragma once
// Particles leaving the run (`grid.particles_leaving: remove`): one description of which leave
// and where the others move, and the in-place compaction every holder of per-particle data uses
// (the particle fields, the transfer's material indices, each physics' own arrays and lists).
// In place: a shrinking std::vector keeps its storage, so views of it stay valid.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace frostmpm {

/// `leaving[p]` is 1 for each particle that leaves,
/// `new_index[p]` the index particle p keeps afterwards (-1 when it leaves). A physics counts
/// what the leaving particles carry (its balances stay closed), then compacts its own
/// per-particle arrays and particle lists with compact() and remap().
struct ParticleRemoval {
  std::span<const std::uint8_t> leaving;
  std::vector<std::int64_t> new_index;
  std::size_t remaining = 0;
  bool restoring = false;  ///< a restart re-applying earlier removals: nothing to count

  explicit ParticleRemoval(std::span<const std::uint8_t> leaving_particles) : leaving(leaving_particles) {
    new_index.resize(leaving.size());
    for (std::size_t p = 0; p < leaving.size(); ++p)
      new_index[p] = leaving[p] ? -1 : static_cast<std::int64_t>(remaining++);
  }
  /// Keeps the values of every remaining particle, in order (an array of any whole number of
  /// values per particle; one of another length, such as an empty one, is left alone).
  template <class T>
  void compact(std::vector<T>& values) const {
    if (leaving.empty() || values.empty() || values.size() % leaving.size() != 0) return;
    compact(values, values.size() / leaving.size());
  }
  /// The same with `per_particle` values per particle.
  template <class T>
  void compact(std::vector<T>& values, std::size_t per_particle) const {
    std::size_t out = 0;
    for (std::size_t p = 0; p < leaving.size(); ++p) {
      if (leaving[p]) continue;
      for (std::size_t c = 0; c < per_particle; ++c) values[out * per_particle + c] = values[p * per_particle + c];
      ++out;
    }
    values.resize(out * per_particle);
  }
  /// A list of particle indices: the leaving ones dropped, the others renumbered.
  void remap(std::vector<std::size_t>& particles) const {
    std::size_t out = 0;
    for (std::size_t p : particles)
      if (!leaving[p]) particles[out++] = static_cast<std::size_t>(new_index[p]);
    particles.resize(out);
  }
};

}  // namespace frostmpm
