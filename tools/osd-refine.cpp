// osd-refine: uniform Catmull-Clark refinement by OpenSubdiv, the independent reference
// for texgeo's CPU and GPU subdivision (SPEC §5.1, STACK.md "OpenSubdiv facts").
//
//   osd-refine IN LEVEL [OUT] [--repeat N] [--sparse]
//              [--boundary none|edge-only|edge-and-corner] [--crease-method uniform|chaikin]
//              [--triangles catmark|smooth]
//
// IN is an OFF or OBJ file. OBJ: `v` and `f` lines, and the tags of OpenSubdiv's
// regression shapes (`t NAME nint/nfloat/nstring ints floats strings`, vertex and face
// indices 0-based): `crease` (vertex pairs, one sharpness for all or one per pair),
// `corner` (vertices, one sharpness or one each), `hole` (faces), `interpolateboundary`
// (0 none, 1 edge-and-corner, 2 edge-only), `creasemethod` (normal|chaikin),
// `smoothtriangles` (catmark|smooth); other tags are ignored. The mesh is refined LEVEL
// times with Sdc::SCHEME_CATMARK, FVAR_LINEAR_ALL and by default VTX_BOUNDARY_EDGE_ONLY,
// CREASE_UNIFORM, TRI_SUB_CATMARK (the tags, then the options, change these), with full
// topology in the last level (--sparse drops it, as an application that only draws
// would), positions interpolated in double precision. The last level is written to OUT
// as OFF with %.17g coordinates, in OpenSubdiv's default vertex order (vertex points,
// face points, edge points), leaving out faces under holes (their vertices stay).
//
// With --repeat N, topology creation + refinement + interpolation is timed N times (the
// previous run's result is freed outside the timed region) and one line is printed on
// stdout:
//   osd-refine: level=L vertices=V faces=F repeat=N min_seconds=S median_seconds=M
// Errors go to stderr as `file:line: message` and exit with status 1.
//
// Face indices are range-checked here (OpenSubdiv itself does not check them), and so are
// the tags: a crease on vertices no edge joins, a corner or hole out of range, a negative
// sharpness are errors (OpenSubdiv would only warn or clamp).

#include <opensubdiv/far/primvarRefiner.h>
#include <opensubdiv/far/topologyDescriptor.h>
#include <opensubdiv/far/topologyRefinerFactory.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

using namespace OpenSubdiv;

namespace {

struct Mesh {
    std::vector<double> positions;  // xyz per vertex
    std::vector<int> faceSizes;
    std::vector<int> faceIndices;
    // Sharp features and scheme options from OBJ tags.
    std::vector<int> creaseVertices;  // pairs
    std::vector<float> creaseWeights;
    std::vector<int> cornerVertices;
    std::vector<float> cornerWeights;
    std::vector<int> holes;
    Sdc::Options options;
    int numVertices() const { return int(positions.size() / 3); }
};

Sdc::Options defaultOptions() {
    Sdc::Options sdc;
    sdc.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    sdc.SetFVarLinearInterpolation(Sdc::Options::FVAR_LINEAR_ALL);
    sdc.SetCreasingMethod(Sdc::Options::CREASE_UNIFORM);
    sdc.SetTriangleSubdivision(Sdc::Options::TRI_SUB_CATMARK);
    return sdc;
}

// A primvar in double precision for PrimvarRefinerReal<double>.
struct Point {
    double p[3];
    void Clear() { p[0] = p[1] = p[2] = 0.0; }
    void AddWithWeight(Point const& src, double w) {
        p[0] += w * src.p[0];
        p[1] += w * src.p[1];
        p[2] += w * src.p[2];
    }
};

[[noreturn]] void fail(std::string const& where, std::string const& message) {
    std::fprintf(stderr, "osd-refine: %s: %s\n", where.c_str(), message.c_str());
    std::exit(1);
}

std::string at(std::string const& path, long line) { return path + ":" + std::to_string(line); }

bool parseDouble(std::string const& tok, double& out) {
    if (tok.empty()) return false;
    char* end = nullptr;
    errno = 0;
    out = std::strtod(tok.c_str(), &end);
    return end == tok.c_str() + tok.size() && errno != ERANGE && std::isfinite(out);
}

bool parseLong(std::string const& tok, long& out) {
    if (tok.empty()) return false;
    char* end = nullptr;
    errno = 0;
    out = std::strtol(tok.c_str(), &end, 10);
    return end == tok.c_str() + tok.size() && errno != ERANGE;
}

// The non-blank lines of a file with `#` comments removed, with 1-based line numbers.
struct Lines {
    std::ifstream in;
    std::string path;
    long number = 0;
    bool next(std::string& line) {
        while (std::getline(in, line)) {
            ++number;
            auto hash = line.find('#');
            if (hash != std::string::npos) line.erase(hash);
            if (line.find_first_not_of(" \t\r") != std::string::npos) return true;
        }
        return false;
    }
};

std::vector<std::string> tokens(std::string const& line) {
    std::istringstream s(line);
    std::vector<std::string> out;
    std::string t;
    while (s >> t) out.push_back(t);
    return out;
}

void checkFace(Mesh const& mesh, std::string const& where, int first) {
    int size = int(mesh.faceIndices.size()) - first;
    if (size < 3) fail(where, "a face needs at least 3 vertices, this one has " + std::to_string(size));
}

Mesh readOff(std::string const& path) {
    Lines lines{std::ifstream(path), path};
    if (!lines.in) fail(path, std::strerror(errno));
    Mesh mesh;
    mesh.options = defaultOptions();
    std::string line;
    if (!lines.next(line)) fail(path, "empty file, expected an OFF header");
    auto head = tokens(line);
    if (head[0] != "OFF" && head[0] != "COFF" && head[0] != "NOFF" && head[0] != "CNOFF")
        fail(at(path, lines.number), "expected an OFF header, found '" + head[0] + "'");
    std::vector<std::string> counts(head.begin() + 1, head.end());
    if (counts.empty()) {
        if (!lines.next(line)) fail(at(path, lines.number), "the file ends before the counts");
        counts = tokens(line);
    }
    long nv = 0, nf = 0;
    if (counts.size() < 2 || !parseLong(counts[0], nv) || !parseLong(counts[1], nf) || nv < 0 || nf < 0 ||
        nv > std::numeric_limits<int>::max() || nf > std::numeric_limits<int>::max())
        fail(at(path, lines.number), "expected 'vertices faces [edges]' counts");
    for (long i = 0; i < nv; ++i) {
        if (!lines.next(line)) fail(at(path, lines.number), "the file ends after " + std::to_string(i) + " vertices");
        auto t = tokens(line);
        double x, y, z;
        if (t.size() < 3 || !parseDouble(t[0], x) || !parseDouble(t[1], y) || !parseDouble(t[2], z))
            fail(at(path, lines.number), "a vertex needs three finite coordinates");
        mesh.positions.insert(mesh.positions.end(), {x, y, z});
    }
    for (long i = 0; i < nf; ++i) {
        if (!lines.next(line)) fail(at(path, lines.number), "the file ends after " + std::to_string(i) + " faces");
        auto t = tokens(line);
        long n = 0;
        if (!parseLong(t[0], n) || n < 3) fail(at(path, lines.number), "a face needs a size of at least 3");
        if (long(t.size()) < n + 1) fail(at(path, lines.number), "the face lists fewer vertices than its size");
        int first = int(mesh.faceIndices.size());
        for (long j = 1; j <= n; ++j) {
            long v = 0;
            if (!parseLong(t[j], v) || v < 0 || v >= nv)
                fail(at(path, lines.number), "vertex index '" + t[j] + "' is out of range (the file has " +
                                                 std::to_string(nv) + " vertices)");
            mesh.faceIndices.push_back(int(v));
        }
        mesh.faceSizes.push_back(int(n));
        checkFace(mesh, at(path, lines.number), first);
    }
    return mesh;
}

bool parseFloat(std::string const& tok, float& out) {
    double d = 0.0;
    if (!parseDouble(tok, d)) return false;
    out = float(d);
    return true;
}

// One `t NAME nint/nfloat/nstring ints floats strings` line (indices 0-based, checked
// once the whole file is read).
void readTag(Mesh& mesh, std::vector<std::string> const& t, std::string const& where) {
    if (t.size() < 3) fail(where, "a tag needs a name and 'nint/nfloat/nstring' counts");
    long n[3] = {0, 0, 0};
    std::string counts = t[2];
    for (int k = 0; k < 3; ++k) {
        size_t slash = counts.find('/');
        std::string part = counts.substr(0, slash);
        if (!parseLong(part, n[k]) || n[k] < 0 || (k < 2 && slash == std::string::npos))
            fail(where, "expected 'nint/nfloat/nstring' counts, found '" + t[2] + "'");
        counts = slash == std::string::npos ? "" : counts.substr(slash + 1);
    }
    if (long(t.size()) != 3 + n[0] + n[1] + n[2])
        fail(where, "the tag announces " + std::to_string(n[0] + n[1] + n[2]) + " arguments, found " +
                        std::to_string(t.size() - 3));
    std::vector<int> ints;
    std::vector<float> floats;
    std::vector<std::string> strings;
    for (long k = 0; k < n[0]; ++k) {
        long v = 0;
        if (!parseLong(t[3 + k], v) || v < 0 || v > std::numeric_limits<int>::max())
            fail(where, "'" + t[3 + k] + "' is not an index");
        ints.push_back(int(v));
    }
    for (long k = 0; k < n[1]; ++k) {
        float v = 0;
        if (!parseFloat(t[3 + n[0] + k], v) || v < 0) fail(where, "'" + t[3 + n[0] + k] + "' is not a sharpness");
        floats.push_back(v);
    }
    for (long k = 0; k < n[2]; ++k) strings.push_back(t[3 + n[0] + n[1] + k]);
    std::string const& name = t[1];
    auto weight = [&](size_t i, size_t items) {
        if (floats.size() == 1) return floats[0];
        if (floats.size() == items) return floats[i];
        fail(where, "'" + name + "' needs one sharpness or one per item");
    };
    if (name == "crease") {
        if (ints.empty() || ints.size() % 2 != 0) fail(where, "'crease' needs vertex pairs");
        for (size_t i = 0; i < ints.size() / 2; ++i) {
            mesh.creaseVertices.push_back(ints[2 * i]);
            mesh.creaseVertices.push_back(ints[2 * i + 1]);
            mesh.creaseWeights.push_back(weight(i, ints.size() / 2));
        }
    } else if (name == "corner") {
        for (size_t i = 0; i < ints.size(); ++i) {
            mesh.cornerVertices.push_back(ints[i]);
            mesh.cornerWeights.push_back(weight(i, ints.size()));
        }
    } else if (name == "hole") {
        mesh.holes.insert(mesh.holes.end(), ints.begin(), ints.end());
    } else if (name == "interpolateboundary") {
        if (ints.size() != 1) fail(where, "'interpolateboundary' takes one integer");
        switch (ints[0]) {
            case 0: mesh.options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_NONE); break;
            case 1: mesh.options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER); break;
            case 2: mesh.options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY); break;
            default: fail(where, "'interpolateboundary' is 0, 1 or 2");
        }
    } else if (name == "creasemethod") {
        if (strings.size() != 1) fail(where, "'creasemethod' takes one string");
        if (strings[0] == "normal" || strings[0] == "uniform") {
            mesh.options.SetCreasingMethod(Sdc::Options::CREASE_UNIFORM);
        } else if (strings[0] == "chaikin") {
            mesh.options.SetCreasingMethod(Sdc::Options::CREASE_CHAIKIN);
        } else {
            fail(where, "'creasemethod' is normal or chaikin");
        }
    } else if (name == "smoothtriangles") {
        if (strings.size() != 1) fail(where, "'smoothtriangles' takes one string");
        if (strings[0] == "catmark") {
            mesh.options.SetTriangleSubdivision(Sdc::Options::TRI_SUB_CATMARK);
        } else if (strings[0] == "smooth") {
            mesh.options.SetTriangleSubdivision(Sdc::Options::TRI_SUB_SMOOTH);
        } else {
            fail(where, "'smoothtriangles' is catmark or smooth");
        }
    }
    // Other tags (face-varying options, hierarchical edits, ...) do not change positions
    // here and are ignored.
}

// The tags' indices against the mesh: every crease pair joined by an edge, corners and
// holes in range.
void checkTags(Mesh const& mesh, std::string const& path) {
    std::vector<std::pair<int, int>> edges;
    for (size_t f = 0, first = 0; f < mesh.faceSizes.size(); first += mesh.faceSizes[f], ++f) {
        for (int j = 0; j < mesh.faceSizes[f]; ++j) {
            int a = mesh.faceIndices[first + j], b = mesh.faceIndices[first + (j + 1) % mesh.faceSizes[f]];
            edges.emplace_back(std::min(a, b), std::max(a, b));
        }
    }
    std::sort(edges.begin(), edges.end());
    for (size_t i = 0; i < mesh.creaseWeights.size(); ++i) {
        int a = mesh.creaseVertices[2 * i], b = mesh.creaseVertices[2 * i + 1];
        if (!std::binary_search(edges.begin(), edges.end(), std::make_pair(std::min(a, b), std::max(a, b))))
            fail(path, "crease: vertices " + std::to_string(a) + " and " + std::to_string(b) +
                           " are not joined by an edge");
    }
    for (int v : mesh.cornerVertices)
        if (v >= mesh.numVertices()) fail(path, "corner: vertex " + std::to_string(v) + " is out of range");
    for (int f : mesh.holes)
        if (f >= int(mesh.faceSizes.size())) fail(path, "hole: face " + std::to_string(f) + " is out of range");
}

// OBJ: `v x y z` and `f a b c …` (a, b, c may be `i`, `i/t`, `i//n`, `i/t/n`, negative = relative).
Mesh readObj(std::string const& path) {
    Lines lines{std::ifstream(path), path};
    if (!lines.in) fail(path, std::strerror(errno));
    Mesh mesh;
    mesh.options = defaultOptions();
    std::string line;
    while (lines.next(line)) {
        auto t = tokens(line);
        if (t[0] == "v") {
            double x, y, z;
            if (t.size() < 4 || !parseDouble(t[1], x) || !parseDouble(t[2], y) || !parseDouble(t[3], z))
                fail(at(path, lines.number), "a vertex needs three finite coordinates");
            mesh.positions.insert(mesh.positions.end(), {x, y, z});
        } else if (t[0] == "f") {
            int first = int(mesh.faceIndices.size());
            for (size_t j = 1; j < t.size(); ++j) {
                std::string idx = t[j].substr(0, t[j].find('/'));
                long v = 0;
                if (!parseLong(idx, v) || v == 0) fail(at(path, lines.number), "bad vertex index '" + t[j] + "'");
                long nv = mesh.numVertices();
                long i = v > 0 ? v - 1 : nv + v;  // indices refer to the vertices read so far
                if (i < 0 || i >= nv)
                    fail(at(path, lines.number), "vertex index " + std::to_string(v) + " is out of range (" +
                                                     std::to_string(nv) + " vertices so far)");
                mesh.faceIndices.push_back(int(i));
            }
            checkFace(mesh, at(path, lines.number), first);
            mesh.faceSizes.push_back(int(mesh.faceIndices.size()) - first);
        } else if (t[0] == "t") {
            readTag(mesh, t, at(path, lines.number));
        }
    }
    return mesh;
}

bool endsWith(std::string const& s, std::string const& suffix) {
    if (s.size() < suffix.size()) return false;
    return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(),
                      [](char a, char b) { return std::tolower(a) == std::tolower(b); });
}

struct Result {
    std::unique_ptr<Far::TopologyRefiner> refiner;
    std::vector<Point> points;  // every level, concatenated
};

// Topology creation, uniform refinement and interpolation of every level: what is timed.
Result refine(Mesh const& mesh, int level, bool fullTopology) {
    Sdc::Options sdc = mesh.options;

    Far::TopologyDescriptor desc;
    desc.numVertices = mesh.numVertices();
    desc.numFaces = int(mesh.faceSizes.size());
    desc.numVertsPerFace = mesh.faceSizes.data();
    desc.vertIndicesPerFace = mesh.faceIndices.data();
    desc.numCreases = int(mesh.creaseWeights.size());
    desc.creaseVertexIndexPairs = mesh.creaseVertices.data();
    desc.creaseWeights = mesh.creaseWeights.data();
    desc.numCorners = int(mesh.cornerWeights.size());
    desc.cornerVertexIndices = mesh.cornerVertices.data();
    desc.cornerWeights = mesh.cornerWeights.data();
    desc.numHoles = int(mesh.holes.size());
    desc.holeIndices = mesh.holes.data();

    using Factory = Far::TopologyRefinerFactory<Far::TopologyDescriptor>;
    Result r;
    r.refiner.reset(Factory::Create(desc, Factory::Options(Sdc::SCHEME_CATMARK, sdc)));
    if (!r.refiner) fail("OpenSubdiv", "TopologyRefinerFactory::Create failed");

    Far::TopologyRefiner::UniformOptions uniform(level);
    uniform.fullTopologyInLastLevel = fullTopology;
    r.refiner->RefineUniform(uniform);

    r.points.resize(r.refiner->GetNumVerticesTotal());
    for (int v = 0; v < desc.numVertices; ++v)
        for (int k = 0; k < 3; ++k) r.points[v].p[k] = mesh.positions[3 * v + k];
    Far::PrimvarRefinerReal<double> primvar(*r.refiner);
    Point* src = r.points.data();
    for (int l = 1; l <= level; ++l) {
        Point* dst = src + r.refiner->GetLevel(l - 1).GetNumVertices();
        primvar.Interpolate(l, src, dst);
        src = dst;
    }
    return r;
}

void writeOff(std::string const& path, Result const& r) {
    int level = r.refiner->GetMaxLevel();
    Far::TopologyLevel const& last = r.refiner->GetLevel(level);
    Point const* p = r.points.data() + (r.points.size() - last.GetNumVertices());
    FILE* out = std::fopen(path.c_str(), "w");
    if (!out) fail(path, std::strerror(errno));
    int kept = 0;
    for (int f = 0; f < last.GetNumFaces(); ++f) kept += !last.IsFaceHole(f);
    std::fprintf(out, "OFF\n%d %d 0\n", last.GetNumVertices(), kept);
    for (int v = 0; v < last.GetNumVertices(); ++v)
        std::fprintf(out, "%.17g %.17g %.17g\n", p[v].p[0], p[v].p[1], p[v].p[2]);
    for (int f = 0; f < last.GetNumFaces(); ++f) {
        if (last.IsFaceHole(f)) continue;
        Far::ConstIndexArray fv = last.GetFaceVertices(f);
        std::fprintf(out, "%d", fv.size());
        for (int j = 0; j < fv.size(); ++j) std::fprintf(out, " %d", fv[j]);
        std::fputc('\n', out);
    }
    if (std::fclose(out) != 0) fail(path, std::strerror(errno));
}

[[noreturn]] void usage() {
    std::fprintf(stderr,
                 "usage: osd-refine IN.(off|obj) LEVEL [OUT.off] [--repeat N] [--sparse]\n"
                 "       [--boundary none|edge-only|edge-and-corner] [--crease-method uniform|chaikin]\n"
                 "       [--triangles catmark|smooth]\n");
    std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
    std::vector<std::string> positional;
    long repeat = 0;
    bool fullTopology = true;
    std::string boundary, creaseMethod, triangles;
    for (int i = 1; i < argc; ++i) {
        std::string a = argv[i];
        if (a == "--repeat") {
            if (i + 1 >= argc || !parseLong(argv[i + 1], repeat) || repeat < 1) usage();
            ++i;
        } else if (a == "--boundary" || a == "--crease-method" || a == "--triangles") {
            if (i + 1 >= argc) usage();
            (a == "--boundary" ? boundary : a == "--crease-method" ? creaseMethod : triangles) = argv[++i];
        } else if (a == "--sparse") {
            fullTopology = false;
        } else if (a.size() > 1 && a[0] == '-') {
            usage();
        } else {
            positional.push_back(a);
        }
    }
    long level = 0;
    if (positional.size() < 2 || positional.size() > 3 || !parseLong(positional[1], level)) usage();
    if (level < 1 || level > 10) fail("LEVEL", "must be in 1..=10, got " + positional[1]);

    std::string const& in = positional[0];
    Mesh mesh = endsWith(in, ".obj") ? readObj(in) : readOff(in);
    if (mesh.faceSizes.empty()) fail(in, "the mesh has no faces");
    checkTags(mesh, in);
    if (boundary == "none") {
        mesh.options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_NONE);
    } else if (boundary == "edge-only") {
        mesh.options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_ONLY);
    } else if (boundary == "edge-and-corner") {
        mesh.options.SetVtxBoundaryInterpolation(Sdc::Options::VTX_BOUNDARY_EDGE_AND_CORNER);
    } else if (!boundary.empty()) {
        usage();
    }
    if (creaseMethod == "uniform") {
        mesh.options.SetCreasingMethod(Sdc::Options::CREASE_UNIFORM);
    } else if (creaseMethod == "chaikin") {
        mesh.options.SetCreasingMethod(Sdc::Options::CREASE_CHAIKIN);
    } else if (!creaseMethod.empty()) {
        usage();
    }
    if (triangles == "catmark") {
        mesh.options.SetTriangleSubdivision(Sdc::Options::TRI_SUB_CATMARK);
    } else if (triangles == "smooth") {
        mesh.options.SetTriangleSubdivision(Sdc::Options::TRI_SUB_SMOOTH);
    } else if (!triangles.empty()) {
        usage();
    }

    Result r;
    std::vector<double> seconds;
    for (long k = 0; k < std::max(repeat, 1L); ++k) {
        r = Result();
        auto t0 = std::chrono::steady_clock::now();
        r = refine(mesh, int(level), fullTopology);
        auto t1 = std::chrono::steady_clock::now();
        seconds.push_back(std::chrono::duration<double>(t1 - t0).count());
    }
    if (repeat > 0) {
        std::sort(seconds.begin(), seconds.end());
        size_t n = seconds.size();
        double median = n % 2 == 1 ? seconds[n / 2] : 0.5 * (seconds[n / 2 - 1] + seconds[n / 2]);
        Far::TopologyLevel const& last = r.refiner->GetLevel(int(level));
        std::printf("osd-refine: level=%ld vertices=%d faces=%d repeat=%ld min_seconds=%.6f median_seconds=%.6f\n",
                    level, last.GetNumVertices(), last.GetNumFaces(), repeat, seconds[0], median);
    }
    if (positional.size() == 3) writeOff(positional[2], r);
    return 0;
}
