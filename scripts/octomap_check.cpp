// octomap_check: cross-checks fuzzyvox against the OctoMap library itself.
//
// Every subcommand prints exactly one line of JSON on standard output; errors go to
// standard error with a non-zero exit status.
//
//   octomap_check count FILE                  census of a .bt or .ot OcTree
//   octomap_check path FILE RADIUS PLAN_JSON  clearance of a `fuzzyvox plan --json` path
//   octomap_check build SCAN RES OUT_BASE     OctoMap's own map of an ASCII `x y z` scan
//
// fuzzyvox's tests build it (tests/octomap_formats.rs, tests/octomap_maps.rs); by hand, with
// Debian's liboctomap-dev:
//
//   g++ -O2 -std=c++17 scripts/octomap_check.cpp -o target/octomap_check -loctomap -loctomath
#include <octomap/octomap.h>
#include <octomap/OcTree.h>

#include <sys/resource.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

using octomap::OcTree;
using octomap::OcTreeNode;
using octomap::point3d;

namespace {

[[noreturn]] void fail(const std::string& message) {
  std::cerr << "octomap_check: " << message << "\n";
  std::exit(2);
}

// A string as a JSON string literal (file names may hold quotes or backslashes).
std::string quoted(const std::string& s) {
  std::string out = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') { out += '\\'; out += static_cast<char>(c); }
    else if (c < 0x20) { char buf[8]; std::snprintf(buf, sizeof buf, "\\u%04x", c); out += buf; }
    else out += static_cast<char>(c);
  }
  return out + "\"";
}

// A double in JSON: full precision, and `null` for "none found" (NaN/inf).
std::string number(double x) {
  if (!std::isfinite(x)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", x);
  return buf;
}

// Peak resident set size of this process so far, in KiB (Linux reports ru_maxrss in KiB).
long max_rss_kb() {
  struct rusage usage {};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}

// Loads an OcTree, choosing the reader by the file's first line (not its extension):
// "# Octomap OcTree binary file" -> OcTree::readBinary, "# Octomap OcTree file" ->
// AbstractOcTree::read, which must yield a plain OcTree (not e.g. a ColorOcTree).
std::unique_ptr<OcTree> load(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) fail("cannot open " + file);
  std::string first;
  std::getline(in, first);
  if (!first.empty() && first.back() == '\r') first.pop_back();
  in.close();
  if (first.rfind("# Octomap OcTree binary file", 0) == 0) {
    auto tree = std::make_unique<OcTree>(0.1);  // the resolution is read from the file
    if (!tree->readBinary(file)) fail("OcTree::readBinary failed on " + file);
    return tree;
  }
  if (first.rfind("# Octomap OcTree file", 0) == 0) {
    std::unique_ptr<octomap::AbstractOcTree> abstract(octomap::AbstractOcTree::read(file));
    if (!abstract) fail("AbstractOcTree::read failed on " + file);
    auto* tree = dynamic_cast<OcTree*>(abstract.get());
    if (!tree) fail(file + " holds a " + abstract->getTreeType() + ", not an OcTree; refusing it");
    abstract.release();
    return std::unique_ptr<OcTree>(tree);
  }
  fail(file + " is neither an OctoMap .bt nor .ot file (first line: \"" + first + "\")");
}

// Leaf census: leaves, and the finest-level voxels they cover, split by occupancy.
struct Census {
  uint64_t leaves = 0, occupied_leaves = 0, free_leaves = 0;
  uint64_t occupied_voxels = 0, free_voxels = 0;
};

Census census(const OcTree& tree) {
  Census c;
  const unsigned depth = tree.getTreeDepth();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    // A leaf at depth d stands for (2^(depth-d))^3 voxels of the finest level.
    const uint64_t voxels = uint64_t{1} << (3 * (depth - it.getDepth()));
    ++c.leaves;
    if (tree.isNodeOccupied(*it)) { ++c.occupied_leaves; c.occupied_voxels += voxels; }
    else { ++c.free_leaves; c.free_voxels += voxels; }
  }
  return c;
}

int cmd_count(const std::string& file) {
  auto tree = load(file);
  const long rss = max_rss_kb();  // after loading, before the census
  const Census c = census(*tree);
  std::cout << "{\"file\":" << quoted(file) << ",\"resolution\":" << number(tree->getResolution())
            << ",\"tree_depth\":" << tree->getTreeDepth() << ",\"leaves\":" << c.leaves
            << ",\"occupied_leaves\":" << c.occupied_leaves << ",\"free_leaves\":" << c.free_leaves
            << ",\"occupied_voxels\":" << c.occupied_voxels << ",\"free_voxels\":" << c.free_voxels
            << ",\"nodes\":" << tree->size() << ",\"memory_bytes\":" << tree->memoryUsage()
            << ",\"memory_full_grid_bytes\":" << tree->memoryFullGrid() << ",\"max_rss_kb\":" << rss
            << "}\n";
  return 0;
}

// Minimal reader for the "waypoints" key of `fuzzyvox plan --json`: an array of [x,y,z]
// arrays. It looks for the quoted key followed (after whitespace) by a colon, then reads
// every number up to the bracket that closes the outer array.
std::vector<point3d> read_waypoints(const std::string& file) {
  std::ifstream in(file);
  if (!in) fail("cannot open " + file);
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  size_t pos = 0;
  for (;;) {
    pos = text.find("\"waypoints\"", pos);
    if (pos == std::string::npos) fail(file + " has no \"waypoints\" key (did the plan fail?)");
    pos += 11;
    size_t after = text.find_first_not_of(" \t\r\n", pos);
    if (after != std::string::npos && text[after] == ':') { pos = after + 1; break; }
  }
  pos = text.find_first_not_of(" \t\r\n", pos);
  if (pos == std::string::npos || text[pos] != '[') fail("\"waypoints\" in " + file + " is not an array");
  std::vector<double> values;
  int level = 0;
  const char* s = text.c_str();
  for (size_t i = pos; i < text.size();) {
    const char ch = text[i];
    if (ch == '[') { ++level; ++i; }
    else if (ch == ']') { if (--level == 0) break; ++i; }
    else if (ch == ',' || std::isspace(static_cast<unsigned char>(ch))) { ++i; }
    else {
      char* stop = nullptr;
      const double v = std::strtod(s + i, &stop);
      if (stop == s + i) fail("unexpected character in \"waypoints\" of " + file);
      values.push_back(v);
      i = static_cast<size_t>(stop - s);
    }
  }
  if (level != 0 || values.size() % 3 != 0) fail("malformed \"waypoints\" array in " + file);
  std::vector<point3d> points;
  for (size_t i = 0; i + 2 < values.size(); i += 3) points.emplace_back(values[i], values[i + 1], values[i + 2]);
  return points;
}

int cmd_path(const std::string& file, double radius, const std::string& plan) {
  auto tree = load(file);
  const std::vector<point3d> waypoints = read_waypoints(plan);
  if (waypoints.empty()) fail(plan + " has no waypoints");
  const double res = tree->getResolution();
  const double step = res / 10.0;

  // Samples every res/10 m along each segment, endpoints included; a waypoint shared by two
  // segments is sampled once.
  std::vector<point3d> samples{waypoints.front()};
  for (size_t k = 1; k < waypoints.size(); ++k) {
    const point3d a = waypoints[k - 1], b = waypoints[k];
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm() / step)));
    for (int i = 1; i <= n; ++i) samples.push_back(a + (b - a) * (static_cast<float>(i) / n));
  }

  const double reach = radius + res;  // search box half-width: radius plus one voxel of margin
  double min_cube = INFINITY, min_centre = INFINITY;
  uint64_t violations_cube = 0, violations_centre = 0, unknown = 0, occupied = 0;
  for (const point3d& p : samples) {
    const OcTreeNode* here = tree->search(p);
    if (!here) ++unknown;
    else if (tree->isNodeOccupied(here)) ++occupied;

    // leaf_bbx_iterator yields every leaf whose cube intersects the box (pruned leaves may
    // reach far outside it), so distances are measured per leaf, exactly, below.
    const point3d lo(p.x() - reach, p.y() - reach, p.z() - reach);
    const point3d hi(p.x() + reach, p.y() + reach, p.z() + reach);
    double cube = INFINITY, centre = INFINITY;
    for (auto it = tree->begin_leafs_bbx(lo, hi), end = tree->end_leafs_bbx(); it != end; ++it) {
      if (!tree->isNodeOccupied(*it)) continue;
      const point3d c = it.getCoordinate();
      const double half = it.getSize() / 2.0;
      double box2 = 0.0, centre2 = 0.0;
      for (unsigned axis = 0; axis < 3; ++axis) {
        const double d = std::fabs(double(p(axis)) - double(c(axis)));
        const double outside = std::max(0.0, d - half);  // point-to-box gap on this axis
        box2 += outside * outside;
        centre2 += d * d;
      }
      cube = std::min(cube, std::sqrt(box2));
      centre = std::min(centre, std::sqrt(centre2));
    }
    // No occupied leaf in the box means farther than the radius: no violation.
    if (cube < radius) ++violations_cube;
    if (centre < radius) ++violations_centre;
    min_cube = std::min(min_cube, cube);
    min_centre = std::min(min_centre, centre);
  }
  std::cout << "{\"samples\":" << samples.size() << ",\"waypoints\":" << waypoints.size()
            << ",\"radius\":" << number(radius) << ",\"min_distance_to_occupied_cube_m\":" << number(min_cube)
            << ",\"min_distance_to_occupied_centre_m\":" << number(min_centre)
            << ",\"violations_cube\":" << violations_cube << ",\"violations_centre\":" << violations_centre
            << ",\"unknown_samples\":" << unknown << ",\"occupied_samples\":" << occupied << "}\n";
  return violations_cube == 0 ? 0 : 1;
}

int cmd_build(const std::string& scan, double res, const std::string& out_base) {
  std::ifstream in(scan);
  if (!in) fail("cannot open " + scan);
  octomap::Pointcloud cloud;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    double x, y, z;
    if (fields >> x >> y >> z) cloud.push_back(float(x), float(y), float(z));  // skips blank/comment lines
  }
  if (cloud.size() == 0) fail(scan + " holds no `x y z` points");

  OcTree tree(res);
  const auto started = std::chrono::steady_clock::now();
  tree.insertPointCloud(cloud, point3d(0, 0, 0));  // sensor at the origin, no max range
  tree.updateInnerOccupancy();
  tree.prune();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();

  // Figures describe the tree as built (full log-odds), before writing.
  const Census c = census(tree);
  const size_t leaves = tree.getNumLeafNodes(), nodes = tree.size(), memory = tree.memoryUsage();
  // .ot first: writeBinary turns the tree into its maximum-likelihood form and prunes it.
  if (!tree.write(out_base + ".ot")) fail("cannot write " + out_base + ".ot");
  if (!tree.writeBinary(out_base + ".bt")) fail("cannot write " + out_base + ".bt");

  std::cout << "{\"points\":" << cloud.size() << ",\"leaves\":" << leaves << ",\"nodes\":" << nodes
            << ",\"memory_bytes\":" << memory << ",\"occupied_voxels\":" << c.occupied_voxels
            << ",\"free_voxels\":" << c.free_voxels << ",\"seconds\":" << number(seconds) << "}\n";
  return 0;
}

[[noreturn]] void usage() {
  std::cerr << "usage: octomap_check count FILE\n"
               "       octomap_check path FILE RADIUS PLAN_JSON\n"
               "       octomap_check build SCAN RES OUT_BASE\n";
  std::exit(2);
}

double parse_positive(const char* text, const char* what) {
  char* stop = nullptr;
  const double v = std::strtod(text, &stop);
  if (stop == text || *stop != '\0' || !(v > 0.0)) fail(std::string(what) + " must be a positive number, got " + text);
  return v;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) usage();
  const std::string cmd = argv[1];
  try {
    if (cmd == "count" && argc == 3) return cmd_count(argv[2]);
    if (cmd == "path" && argc == 5) return cmd_path(argv[2], parse_positive(argv[3], "RADIUS"), argv[4]);
    if (cmd == "build" && argc == 5) return cmd_build(argv[2], parse_positive(argv[3], "RES"), argv[4]);
  } catch (const std::exception& e) {
    fail(e.what());
  }
  usage();
}
