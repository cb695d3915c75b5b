#include "vkcloth/system.hpp"

namespace vkcloth {

const char* to_string(SpringKind kind) {
  switch (kind) {
  case SpringKind::plain: return "plain";
  case SpringKind::structural: return "structural";
  case SpringKind::shear: return "shear";
  case SpringKind::bend: return "bend";
  }
  return "?";
}

void ParticleSystem::finalize() {
  // Counting sort by particle; iterating springs in index order keeps each list sorted by spring
  // index, which fixes the force summation order for every solver.
  const std::size_t n = particles.size();
  adjacency.offsets.assign(n + 1, 0);
  for (const Spring& s : springs) {
    ++adjacency.offsets[s.a + 1];
    ++adjacency.offsets[s.b + 1];
  }
  for (std::size_t p = 0; p < n; ++p) adjacency.offsets[p + 1] += adjacency.offsets[p];
  adjacency.refs.assign(adjacency.offsets[n], SpringRef{});
  std::vector<std::uint32_t> fill(adjacency.offsets.begin(), adjacency.offsets.end() - 1);
  for (std::uint32_t k = 0; k < springs.size(); ++k) {
    const Spring& s = springs[k];
    adjacency.refs[fill[s.a]++] = SpringRef{s.b, k};
    adjacency.refs[fill[s.b]++] = SpringRef{s.a, k};
  }
}

} // namespace vkcloth
