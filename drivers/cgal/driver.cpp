// One CGAL operation on a point file, timed inside the process.
//
//   cgal_driver OP POINTS.npy [--order ORDER.npy] [--count] [--threads T] [--out SIMPLICES.npy]
//
// OP: dt2 | dt3           range insertion of plain points, no vertex info (CGAL
//                         spatially sorts: CGAL at its fastest); the output is
//                         mapped to input indices after the timed region
//     dt2-indexed | dt3-indexed  range insertion of (point, index) pairs through
//                         Triangulation_vertex_base_with_info (what a user who
//                         needs index arrays writes)
//     dt3-parallel        range insertion with Parallel_tag on T TBB threads
//                         (built only when TBB is found: cgal_driver_tbb)
//     dt2-order | dt3-order  one point at a time in ORDER's permutation, each
//                         with its hint (paper 2, section 3.1); ORDER.npy is an
//                         int64 (n, 2) array of (input index, hint index or -1).
//     dt3-hilbert-sort | dt3-spatial-sort  one point at a time in the order of
//                         CGAL's own hilbert_sort (median policy) or
//                         spatial_sort (BRIO rounds of hilbert_sort), each with
//                         the previous vertex as hint; the sort is timed, as
//                         paper 2 includes order building.
// --count  wraps the orientation and in-circle/in-sphere functors with counters
//          and, for *-order, inserts through find_conflicts + insert_in_hole to
//          count conflicting cells.  Without it the plain kernel runs: timed
//          runs pay nothing for counting.
// Prints one JSON line.  File I/O is outside the timed region.
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_triangulation_3.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_3.h>
#include <CGAL/Spatial_sort_traits_adapter_3.h>
#include <CGAL/hilbert_sort.h>
#include <CGAL/property_map.h>
#include <CGAL/spatial_sort.h>
#include <CGAL/version.h>
#include <sys/resource.h>
#include <x86intrin.h>
#ifdef CGAL_LINKED_WITH_TBB
#include <tbb/global_control.h>
#endif

#include <array>
#include <chrono>
#include <memory>
#include <type_traits>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#ifndef LFQT_FLAGS
#define LFQT_FLAGS ""
#endif

typedef CGAL::Exact_predicates_inexact_constructions_kernel Epick;

static std::uint64_t g_orient = 0, g_incircle = 0;

// ---------------------------------------------------------------- .npy I/O
struct Array {
  std::vector<char> data;
  std::string descr;
  std::vector<long> shape;
};

static Array read_npy(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot open " + path);
  char magic[6];
  f.read(magic, 6);
  if (std::memcmp(magic, "\x93NUMPY", 6) != 0) throw std::runtime_error(path + ": not a .npy file");
  unsigned char ver[2];
  f.read(reinterpret_cast<char*>(ver), 2);
  std::uint32_t hlen = 0;
  if (ver[0] == 1) {
    std::uint16_t h16;
    f.read(reinterpret_cast<char*>(&h16), 2);
    hlen = h16;
  } else {
    f.read(reinterpret_cast<char*>(&hlen), 4);
  }
  std::string header(hlen, ' ');
  f.read(&header[0], hlen);
  Array a;
  auto field = [&](const std::string& key) {
    auto p = header.find("'" + key + "'");
    if (p == std::string::npos) throw std::runtime_error(path + ": header lacks " + key);
    return header.substr(header.find(':', p) + 1);
  };
  std::string d = field("descr");
  a.descr = d.substr(d.find('\'') + 1, 3);
  if (field("fortran_order").find("True") < field("fortran_order").find(','))
    throw std::runtime_error(path + ": Fortran order is not supported");
  std::string s = field("shape");
  s = s.substr(s.find('(') + 1, s.find(')') - s.find('(') - 1);
  std::stringstream ss(s);
  std::string tok;
  while (std::getline(ss, tok, ',')) {
    if (tok.find_first_not_of(" ") != std::string::npos) a.shape.push_back(std::stol(tok));
  }
  long count = 1;
  for (long v : a.shape) count *= v;
  a.data.resize(count * 8);
  f.read(a.data.data(), count * 8);
  if (!f) throw std::runtime_error(path + ": truncated data");
  return a;
}

static void write_npy_i64(const std::string& path, const std::vector<std::int64_t>& v, long rows, long cols) {
  std::ostringstream h;
  h << "{'descr': '<i8', 'fortran_order': False, 'shape': (" << rows << ", " << cols << "), }";
  std::string header = h.str();
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::ofstream f(path, std::ios::binary);
  f.write("\x93NUMPY\x01\x00", 8);
  std::uint16_t hl = static_cast<std::uint16_t>(header.size());
  f.write(reinterpret_cast<const char*>(&hl), 2);
  f.write(header.data(), header.size());
  f.write(reinterpret_cast<const char*>(v.data()), v.size() * 8);
}

// ---------------------------------------------------------------- counting traits
struct CountingK : public Epick {
  struct Orientation_2 {
    CGAL::Orientation operator()(const Point_2& p, const Point_2& q, const Point_2& r) const {
      ++g_orient;
      return Epick().orientation_2_object()(p, q, r);
    }
  };
  struct Side_of_oriented_circle_2 {
    CGAL::Oriented_side operator()(const Point_2& p, const Point_2& q, const Point_2& r,
                                   const Point_2& t) const {
      ++g_incircle;
      return Epick().side_of_oriented_circle_2_object()(p, q, r, t);
    }
  };
  struct Orientation_3 {
    CGAL::Orientation operator()(const Point_3& p, const Point_3& q, const Point_3& r,
                                 const Point_3& s) const {
      ++g_orient;
      return Epick().orientation_3_object()(p, q, r, s);
    }
  };
  struct Side_of_oriented_sphere_3 {
    CGAL::Oriented_side operator()(const Point_3& p, const Point_3& q, const Point_3& r,
                                   const Point_3& s, const Point_3& t) const {
      ++g_incircle;
      return Epick().side_of_oriented_sphere_3_object()(p, q, r, s, t);
    }
  };
  Orientation_2 orientation_2_object() const { return Orientation_2(); }
  Side_of_oriented_circle_2 side_of_oriented_circle_2_object() const { return Side_of_oriented_circle_2(); }
  Orientation_3 orientation_3_object() const { return Orientation_3(); }
  Side_of_oriented_sphere_3 side_of_oriented_sphere_3_object() const { return Side_of_oriented_sphere_3(); }
};

// ---------------------------------------------------------------- timing
struct Clock {
  std::chrono::steady_clock::time_point t0;
  unsigned long long c0;
  void start() { t0 = std::chrono::steady_clock::now(); c0 = __rdtsc(); }
  std::pair<double, unsigned long long> stop() const {
    unsigned long long c1 = __rdtsc();
    auto t1 = std::chrono::steady_clock::now();
    return {std::chrono::duration<double>(t1 - t0).count(), c1 - c0};
  }
};

static long current_rss_bytes() {
  long pages = 0, resident = 0;
  FILE* f = std::fopen("/proc/self/statm", "r");
  if (f) {
    if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return resident * 4096L;
}

static long peak_rss_bytes() {
  struct rusage ru;
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_maxrss * 1024L;
}

struct Result {
  double seconds = 0;
  unsigned long long cycles = 0;
  long vertices = 0, cells = 0;
  std::uint64_t conflicts = 0;
  std::vector<std::int64_t> simplices;
};


// ---------------------------------------------------------------- plain range insertion
// Input index of a point from its coordinates' bits (the first of equal rows),
// built after the timed region.
struct IndexOf {
  struct Hash {
    std::size_t operator()(const std::array<std::uint64_t, 3>& k) const {
      return (k[0] * 0x9E3779B97F4A7C15ULL) ^ (k[1] * 0xC2B2AE3D27D4EB4FULL) ^ (k[2] + 0x165667B19E3779F9ULL);
    }
  };
  std::unordered_map<std::array<std::uint64_t, 3>, long, Hash> map;
  static std::array<std::uint64_t, 3> key(double x, double y, double z) {
    std::array<std::uint64_t, 3> k{};
    std::memcpy(&k[0], &x, 8);
    std::memcpy(&k[1], &y, 8);
    std::memcpy(&k[2], &z, 8);
    return k;
  }
  IndexOf(const double* p, long n, int dim) {
    map.reserve(2 * n);
    for (long i = n - 1; i >= 0; --i)
      map[key(p[dim * i], p[dim * i + 1], dim == 3 ? p[dim * i + 2] : 0.0)] = i;
  }
  long operator()(double x, double y, double z = 0.0) const { return map.at(key(x, y, z)); }
};

// Range insertion, timed, with the counters reset.
template <class DT, class Points>
void time_insert(DT& dt, const Points& pts, Result& r) {
  Clock clk;
  g_orient = g_incircle = 0;
  clk.start();
  dt.insert(pts.begin(), pts.end());
  auto t = clk.stop();
  r.seconds = t.first;
  r.cycles = t.second;
}

template <class K>
Result run2_plain(const double* xy, long n) {
  typedef CGAL::Delaunay_triangulation_2<K> DT;
  typedef typename K::Point_2 P;
  std::vector<P> pts;
  pts.reserve(n);
  for (long i = 0; i < n; ++i) pts.emplace_back(xy[2 * i], xy[2 * i + 1]);
  DT dt;
  Result r;
  time_insert(dt, pts, r);
  r.vertices = dt.number_of_vertices();
  r.cells = dt.number_of_faces();
  IndexOf index(xy, n, 2);
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f)
    for (int j = 0; j < 3; ++j) {
      const P& p = f->vertex(j)->point();
      r.simplices.push_back(index(CGAL::to_double(p.x()), CGAL::to_double(p.y())));
    }
  return r;
}

template <class K, class ConcurrencyTag>
Result run3_plain(const double* xyz, long n, int threads) {
  typedef CGAL::Triangulation_data_structure_3<CGAL::Triangulation_vertex_base_3<K>,
                                               CGAL::Delaunay_triangulation_cell_base_3<K>,
                                               ConcurrencyTag> Tds;
  typedef CGAL::Delaunay_triangulation_3<K, Tds> DT;
  typedef typename K::Point_3 P;
  std::vector<P> pts;
  pts.reserve(n);
  for (long i = 0; i < n; ++i) pts.emplace_back(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  Result r;
  DT dt;
  if constexpr (std::is_same<ConcurrencyTag, CGAL::Parallel_tag>::value) {
#ifdef CGAL_LINKED_WITH_TBB
    // as in CGAL's parallel example: a lock grid over the bounding box
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    typename DT::Lock_data_structure locks(CGAL::bbox_3(pts.begin(), pts.end()), 50);
    dt.set_lock_data_structure(&locks);
    time_insert(dt, pts, r);
    dt.set_lock_data_structure(nullptr);
#endif
  } else {
    (void)threads;
    time_insert(dt, pts, r);
  }
  r.vertices = dt.number_of_vertices();
  r.cells = dt.number_of_finite_cells();
  IndexOf index(xyz, n, 3);
  for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c)
    for (int j = 0; j < 4; ++j) {
      const P& p = c->vertex(j)->point();
      r.simplices.push_back(index(CGAL::to_double(p.x()), CGAL::to_double(p.y()),
                                  CGAL::to_double(p.z())));
    }
  return r;
}

// ---------------------------------------------------------------- 2D, indexed or ordered
template <class K>
Result run2(const double* xy, long n, const std::int64_t* order, bool conflicts_mode) {
  typedef CGAL::Triangulation_vertex_base_with_info_2<long, K> Vb;
  typedef CGAL::Triangulation_data_structure_2<Vb> Tds;
  typedef CGAL::Delaunay_triangulation_2<K, Tds> DT;
  typedef typename K::Point_2 P;
  std::vector<std::pair<P, long>> pts;
  pts.reserve(n);
  for (long i = 0; i < n; ++i) pts.emplace_back(P(xy[2 * i], xy[2 * i + 1]), i);
  DT dt;
  Result r;
  Clock clk;
  g_orient = g_incircle = 0;
  clk.start();
  if (!order) {
    dt.insert(pts.begin(), pts.end());
  } else {
    std::vector<typename DT::Vertex_handle> handle(n);
    typename DT::Vertex_handle prev;
    for (long k = 0; k < n; ++k) {
      long i = order[2 * k], h = order[2 * k + 1];
      typename DT::Face_handle hint = typename DT::Face_handle();
      if (h >= 0 && handle[h] != typename DT::Vertex_handle()) hint = handle[h]->face();
      else if (prev != typename DT::Vertex_handle()) hint = prev->face();
      typename DT::Vertex_handle v;
      if (conflicts_mode && dt.dimension() == 2) {
        typename DT::Locate_type lt;
        int li;
        typename DT::Face_handle f = dt.locate(pts[i].first, lt, li, hint);
        if (lt == DT::VERTEX) { v = f->vertex(li); }
        else {
          std::vector<typename DT::Face_handle> faces;
          dt.get_conflicts(pts[i].first, std::back_inserter(faces), f);
          r.conflicts += faces.size();
          v = dt.insert(pts[i].first, f);
        }
      } else {
        v = dt.insert(pts[i].first, hint);
      }
      v->info() = i;
      handle[i] = v;
      prev = v;
    }
  }
  auto t = clk.stop();
  r.seconds = t.first;
  r.cycles = t.second;
  r.vertices = dt.number_of_vertices();
  r.cells = dt.number_of_faces();
  for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f)
    for (int j = 0; j < 3; ++j) r.simplices.push_back(f->vertex(j)->info());
  return r;
}

// ---------------------------------------------------------------- 3D
template <class K>
Result run3(const double* xyz, long n, const std::int64_t* order, bool conflicts_mode,
            int cgal_sort = 0) {
  typedef CGAL::Triangulation_vertex_base_with_info_3<long, K> Vb;
  typedef CGAL::Delaunay_triangulation_cell_base_3<K> Cb;
  typedef CGAL::Triangulation_data_structure_3<Vb, Cb> Tds;
  typedef CGAL::Delaunay_triangulation_3<K, Tds> DT;
  typedef typename K::Point_3 P;
  std::vector<std::pair<P, long>> pts;
  pts.reserve(n);
  for (long i = 0; i < n; ++i) pts.emplace_back(P(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]), i);
  DT dt;
  Result r;
  Clock clk;
  g_orient = g_incircle = 0;
  clk.start();
  std::vector<std::int64_t> sorted_order;
  if (cgal_sort) {  // CGAL's own order (1: hilbert_sort, 2: spatial_sort), previous vertex as hint
    typedef CGAL::Spatial_sort_traits_adapter_3<K, CGAL::First_of_pair_property_map<std::pair<P, long>>> Traits;
    std::vector<std::pair<P, long>> sorted(pts);
    if (cgal_sort == 1) CGAL::hilbert_sort(sorted.begin(), sorted.end(), Traits());
    else CGAL::spatial_sort(sorted.begin(), sorted.end(), Traits());
    sorted_order.resize(2 * n);
    for (long k = 0; k < n; ++k) {
      sorted_order[2 * k] = sorted[k].second;
      sorted_order[2 * k + 1] = -1;
    }
    order = sorted_order.data();
  }
  if (!order) {
    dt.insert(pts.begin(), pts.end());
  } else {
    std::vector<typename DT::Vertex_handle> handle(n);
    typename DT::Vertex_handle prev;
    std::vector<typename DT::Cell_handle> cells;
    for (long k = 0; k < n; ++k) {
      long i = order[2 * k], h = order[2 * k + 1];
      typename DT::Vertex_handle hv = prev;
      if (h >= 0 && handle[h] != typename DT::Vertex_handle()) hv = handle[h];
      typename DT::Vertex_handle v;
      if (conflicts_mode && dt.dimension() == 3) {
        typename DT::Locate_type lt;
        int li, lj;
        typename DT::Cell_handle c = dt.locate(pts[i].first, lt, li, lj,
                                               hv == typename DT::Vertex_handle() ? typename DT::Cell_handle() : hv->cell());
        if (lt == DT::VERTEX) { v = c->vertex(li); }
        else {
          cells.clear();
          typename DT::Facet f;
          dt.find_conflicts(pts[i].first, c, CGAL::Oneset_iterator<typename DT::Facet>(f),
                            std::back_inserter(cells));
          r.conflicts += cells.size();
          v = dt.insert_in_hole(pts[i].first, cells.begin(), cells.end(), f.first, f.second);
        }
      } else {
        v = hv == typename DT::Vertex_handle() ? dt.insert(pts[i].first) : dt.insert(pts[i].first, hv);
      }
      v->info() = i;
      handle[i] = v;
      prev = v;
    }
  }
  auto t = clk.stop();
  r.seconds = t.first;
  r.cycles = t.second;
  r.vertices = dt.number_of_vertices();
  r.cells = dt.number_of_finite_cells();
  for (auto c = dt.finite_cells_begin(); c != dt.finite_cells_end(); ++c)
    for (int j = 0; j < 4; ++j) r.simplices.push_back(c->vertex(j)->info());
  return r;
}

int main(int argc, char** argv) {
  try {
    if (argc < 3) {
      std::fprintf(stderr, "usage: cgal_driver dt2|dt3|dt2-indexed|dt3-indexed|dt3-parallel|"
                           "dt2-order|dt3-order|dt3-hilbert-sort|dt3-spatial-sort POINTS.npy "
                           "[--order ORDER.npy] [--count] "
                           "[--threads T] [--out SIMPLICES.npy]\n");
      return 2;
    }
    std::string op = argv[1], points_path = argv[2], order_path, out_path;
    bool count = false;
    int threads = 1;
    for (int k = 3; k < argc; ++k) {
      std::string a = argv[k];
      if (a == "--count") count = true;
      else if (a == "--threads" && k + 1 < argc) threads = std::stoi(argv[++k]);
      else if (a == "--order" && k + 1 < argc) order_path = argv[++k];
      else if (a == "--out" && k + 1 < argc) out_path = argv[++k];
      else throw std::runtime_error("unknown argument " + a);
    }
    int dim = op.rfind("dt2", 0) == 0 ? 2 : op.rfind("dt3", 0) == 0 ? 3 : 0;
    static const char* ops[] = {"dt2", "dt3", "dt2-indexed", "dt3-indexed", "dt3-parallel",
                                "dt2-order", "dt3-order", "dt3-hilbert-sort", "dt3-spatial-sort"};
    bool known = false;
    for (const char* o : ops) known = known || op == o;
    if (!known) throw std::runtime_error("unknown operation " + op);
#ifndef CGAL_LINKED_WITH_TBB
    if (op == "dt3-parallel") throw std::runtime_error("dt3-parallel needs the TBB build (cgal_driver_tbb)");
#endif
    if (op == "dt3-parallel" && count) throw std::runtime_error("dt3-parallel does not count");
    bool ordered = op.find("-order") != std::string::npos;
    Array pts = read_npy(points_path);
    if (pts.descr != "<f8" || pts.shape.size() != 2 || pts.shape[1] != dim)
      throw std::runtime_error("points must be float64 of shape (n, " + std::to_string(dim) + ")");
    long n = pts.shape[0];
    Array ord;
    const std::int64_t* order = nullptr;
    if (ordered) {
      if (order_path.empty()) throw std::runtime_error(op + " needs --order");
      ord = read_npy(order_path);
      if (ord.descr != "<i8" || ord.shape.size() != 2 || ord.shape[0] != n || ord.shape[1] != 2)
        throw std::runtime_error("order must be int64 of shape (n, 2)");
      order = reinterpret_cast<const std::int64_t*>(ord.data.data());
    }
    const double* xy = reinterpret_cast<const double*>(pts.data.data());
    long baseline = current_rss_bytes();
    bool plain = op == "dt2" || op == "dt3" || op == "dt3-parallel";
    Result r;
    if (plain && dim == 2) {
      r = count ? run2_plain<CountingK>(xy, n) : run2_plain<Epick>(xy, n);
    } else if (plain && op == "dt3") {
      r = count ? run3_plain<CountingK, CGAL::Sequential_tag>(xy, n, 1)
                : run3_plain<Epick, CGAL::Sequential_tag>(xy, n, 1);
    } else if (plain) {
#ifdef CGAL_LINKED_WITH_TBB
      r = run3_plain<Epick, CGAL::Parallel_tag>(xy, n, threads);
#endif
    } else if (dim == 2) {
      r = count ? run2<CountingK>(xy, n, order, ordered) : run2<Epick>(xy, n, order, false);
    } else {
      int cgal_sort = op == "dt3-hilbert-sort" ? 1 : op == "dt3-spatial-sort" ? 2 : 0;
      bool one_by_one = ordered || cgal_sort;
      r = count ? run3<CountingK>(xy, n, order, one_by_one, cgal_sort)
                : run3<Epick>(xy, n, order, false, cgal_sort);
    }
    if (!out_path.empty()) write_npy_i64(out_path, r.simplices, r.simplices.size() / (dim + 1), dim + 1);
    std::printf("{\"op\": \"%s\", \"n\": %ld, \"seconds\": %.9f, \"tsc_cycles\": %llu, "
                "\"vertices\": %ld, \"simplices\": %ld, \"counted\": %s, \"orientation\": %llu, "
                "\"%s\": %llu, \"conflicts\": %llu, \"baseline_rss_bytes\": %ld, "
                "\"peak_rss_bytes\": %ld, \"cgal_version\": \"%s\", \"threads\": %d, "
                "\"compiler\": \"gcc %s\", \"flags\": \"%s\"}\n",
                op.c_str(), n, r.seconds, r.cycles, r.vertices, r.cells, count ? "true" : "false",
                (unsigned long long)g_orient, dim == 2 ? "incircle" : "insphere",
                (unsigned long long)g_incircle, (unsigned long long)r.conflicts, baseline,
                peak_rss_bytes(), CGAL_VERSION_STR, threads, __VERSION__, LFQT_FLAGS);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cgal_driver: %s\n", e.what());
    return 1;
  }
}
