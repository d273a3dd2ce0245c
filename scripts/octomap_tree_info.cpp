// Reads an OctoMap binary tree (.bt) with OctoMap itself and prints one JSON line: resolution,
// node count (tree.size()), leaf count, and occupied and free finest-level voxel counts (a leaf at
// depth d covers 2^(3 (16 - d)) voxels). fuzzyvox's tests use it to check that OctoMap reads the
// .bt files fuzzyvox writes, and to obtain reference numbers for sample files.
//
//   g++ -O2 scripts/octomap_tree_info.cpp -o target/octomap_tree_info -loctomap -loctomath
#include <octomap/octomap.h>

#include <cstdio>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s FILE.bt\n", argv[0]);
    return 2;
  }
  octomap::OcTree tree(0.1);
  if (!tree.readBinary(argv[1])) {
    std::fprintf(stderr, "OctoMap could not read %s\n", argv[1]);
    return 1;
  }
  unsigned long long occupied = 0, free_voxels = 0;
  const unsigned depth = tree.getTreeDepth();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const unsigned long long voxels = 1ULL << (3 * (depth - it.getDepth()));
    if (tree.isNodeOccupied(*it)) {
      occupied += voxels;
    } else {
      free_voxels += voxels;
    }
  }
  std::printf("{\"resolution\":%.17g,\"nodes\":%zu,\"leaves\":%zu,\"occupied\":%llu,\"free\":%llu}\n",
              tree.getResolution(), tree.size(), tree.getNumLeafNodes(), occupied, free_voxels);
  return 0;
}
