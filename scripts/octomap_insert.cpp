// Inserts a plain `x y z` point cloud into an OctoMap OcTree with OctoMap's defaults and prints
// one JSON line: resolution, insert time (the insertPointCloud call alone, median of runs),
// occupied and free finest-level voxel counts, and tree memory. Used by scripts/bench-octomap.
#include <octomap/octomap.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <vector>

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: %s CLOUD RESOLUTION [RUNS]\n", argv[0]);
    return 2;
  }
  const double resolution = std::atof(argv[2]);
  const int runs = argc > 3 ? std::atoi(argv[3]) : 3;
  octomap::Pointcloud cloud;
  std::ifstream in(argv[1]);
  double x, y, z;
  while (in >> x >> y >> z) cloud.push_back(x, y, z);
  std::vector<double> seconds;
  unsigned long long occupied = 0, free_voxels = 0;
  size_t memory = 0;
  for (int run = 0; run < runs; ++run) {
    octomap::OcTree tree(resolution);
    auto start = std::chrono::steady_clock::now();
    tree.insertPointCloud(cloud, octomap::point3d(0, 0, 0));
    auto stop = std::chrono::steady_clock::now();
    seconds.push_back(std::chrono::duration<double>(stop - start).count());
    occupied = free_voxels = 0;
    const unsigned depth = tree.getTreeDepth();
    for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
      unsigned long long voxels = 1ULL << (3 * (depth - it.getDepth()));
      if (tree.isNodeOccupied(*it)) occupied += voxels; else free_voxels += voxels;
    }
    memory = tree.memoryUsage();
  }
  std::sort(seconds.begin(), seconds.end());
  std::printf("{\"points\":%zu,\"resolution\":%g,\"insert_seconds\":%.6f,\"occupied\":%llu,"
              "\"free\":%llu,\"memory_bytes\":%zu}\n",
              cloud.size(), resolution, seconds[seconds.size() / 2], occupied, free_voxels, memory);
  return 0;
}
