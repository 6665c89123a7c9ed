// cgal-boolean: the independent reference for texgeo's Boolean operations (SPEC §6.4).
//
// CGAL 5.5 corefinement (Polygon_mesh_processing::corefine_and_compute_*) with an exact
// kernel (Epeck), on Debian's header-only libcgal-dev. Built by tools/setup into
// target/tools/cgal-boolean; texgeo's driver is src/boolean/cgal.rs.
//
// usage: cgal-boolean A B --op union|intersection|difference|reverse-difference|all
//                     [-o OUT.off] [--repeat N]
//
// Prints the operands' measures (`op=a ...`, `op=b ...`), then for each operation one line
//   op=NAME ok=1 volume=V area=S vertices=NV faces=NF
// or `op=NAME ok=0 reason=...` when CGAL declines (e.g. a non-manifold result), and with
// --repeat N a timing line `op=NAME min_seconds=S median_seconds=S` for the corefinement
// alone (inputs copied before each run; reading and checks not counted). Exit status 2
// with a message on stderr when an input cannot be read or is not a valid solid.

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/IO/polygon_mesh_io.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/triangulate_faces.h>
#include <CGAL/Surface_mesh.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <string>
#include <vector>

typedef CGAL::Exact_predicates_exact_constructions_kernel K;
typedef CGAL::Surface_mesh<K::Point_3> Mesh;
namespace PMP = CGAL::Polygon_mesh_processing;

static void fail(const std::string& message) {
  std::cerr << "cgal-boolean: " << message << std::endl;
  std::exit(2);
}

static Mesh load(const std::string& path) {
  Mesh m;
  if (!PMP::IO::read_polygon_mesh(path, m) || m.is_empty()) fail(path + ": cannot read a polygon mesh");
  if (!CGAL::is_triangle_mesh(m)) PMP::triangulate_faces(m);
  if (!CGAL::is_closed(m)) fail(path + ": not closed");
  if (PMP::does_self_intersect(m)) fail(path + ": self-intersecting");
  if (!PMP::does_bound_a_volume(m)) fail(path + ": does not bound a volume");
  return m;
}

// Runs one corefinement (which modifies its operands: pass copies).
static bool compute(const std::string& op, Mesh& a, Mesh& b, Mesh& out) {
  if (op == "union") return PMP::corefine_and_compute_union(a, b, out);
  if (op == "intersection") return PMP::corefine_and_compute_intersection(a, b, out);
  if (op == "difference") return PMP::corefine_and_compute_difference(a, b, out);
  if (op == "reverse-difference") return PMP::corefine_and_compute_difference(b, a, out);
  fail("unknown operation '" + op + "'");
  return false;
}

int main(int argc, char** argv) {
  std::vector<std::string> pos;
  std::string op, out_path;
  int repeat = 0;
  for (int i = 1; i < argc; ++i) {
    std::string s = argv[i];
    if (s == "--op" && i + 1 < argc) op = argv[++i];
    else if (s == "-o" && i + 1 < argc) out_path = argv[++i];
    else if (s == "--repeat" && i + 1 < argc) repeat = std::atoi(argv[++i]);
    else pos.push_back(s);
  }
  if (pos.size() != 2 || op.empty())
    fail("usage: cgal-boolean A B --op union|intersection|difference|reverse-difference|all "
         "[-o OUT.off] [--repeat N]");
  Mesh a = load(pos[0]);
  Mesh b = load(pos[1]);

  std::vector<std::string> ops;
  if (op == "all") ops = {"union", "intersection", "difference", "reverse-difference"};
  else ops = {op};
  if (!out_path.empty() && ops.size() != 1) fail("-o needs a single --op");

  std::cout << std::setprecision(17);
  // The operands' own measures (the symmetric difference's area needs them).
  std::cout << "op=a ok=1 volume=" << CGAL::to_double(CGAL::exact(PMP::volume(a))) << " area=" << CGAL::to_double(PMP::area(a))
            << " vertices=" << a.number_of_vertices() << " faces=" << a.number_of_faces() << "\n";
  std::cout << "op=b ok=1 volume=" << CGAL::to_double(CGAL::exact(PMP::volume(b))) << " area=" << CGAL::to_double(PMP::area(b))
            << " vertices=" << b.number_of_vertices() << " faces=" << b.number_of_faces() << "\n";
  for (const std::string& name : ops) {
    Mesh out, a1 = a, b1 = b;
    bool ok = false;
    try {
      ok = compute(name, a1, b1, out);
    } catch (const std::exception& e) {
      std::cout << "op=" << name << " ok=0 reason=" << e.what() << "\n";
      continue;
    }
    if (!ok) {
      std::cout << "op=" << name << " ok=0 reason=corefinement-declined\n";
      continue;
    }
    // The exact volume converted (to_double of a lazy number stops at an interval 1e-5
    // wide, which a thin result's cancelling tetrahedra widen to 1e-9 of the volume).
    double volume = out.is_empty() ? 0.0 : CGAL::to_double(CGAL::exact(PMP::volume(out)));
    double area = out.is_empty() ? 0.0 : CGAL::to_double(PMP::area(out));
    std::cout << "op=" << name << " ok=1 volume=" << volume << " area=" << area
              << " vertices=" << out.number_of_vertices() << " faces=" << out.number_of_faces() << "\n";
    if (!out_path.empty() && !CGAL::IO::write_polygon_mesh(out_path, out, CGAL::parameters::stream_precision(17)))
      fail(out_path + ": cannot write");
    if (repeat > 0) {
      std::vector<double> times;
      for (int r = 0; r < repeat; ++r) {
        Mesh a2 = a, b2 = b, o2;
        auto t0 = std::chrono::steady_clock::now();
        compute(name, a2, b2, o2);
        auto t1 = std::chrono::steady_clock::now();
        times.push_back(std::chrono::duration<double>(t1 - t0).count());
      }
      std::sort(times.begin(), times.end());
      std::cout << "op=" << name << " min_seconds=" << times.front()
                << " median_seconds=" << times[times.size() / 2] << "\n";
    }
  }
  std::cout.flush();
  return 0;
}
