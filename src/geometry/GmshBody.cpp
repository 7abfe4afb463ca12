// meshBody: gmsh opens (or imports) the file, meshes it at the target size, raises the mesh to
// order 2 with the new nodes on the geometry, and the particles, volumes and surfaces are read
// off the mesh. The Jacobians are assembled here from the node coordinates and gmsh's Lagrange
// basis gradients (signed, in the plane for 2D), so that orientation and inversion are checked
// on our side.
#include "geometry/GmshBody.hpp"

#include <gmsh.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <clocale>
#include <cmath>
#include <exception>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <numeric>
#include <set>
#include <string_view>
#include <unordered_map>
#include <utility>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "geometry/MessageText.hpp"

namespace tlsph {

namespace {

using geometry_detail::numberText;
using geometry_detail::pointText;
using Tags = std::vector<std::size_t>;

// ---------------------------------------------------------------------------------------------
// The gmsh session: initialise and finalise around one call, collect gmsh's messages, turn its
// exceptions (gmsh 4.8 throws the error text as a std::string) into GeometryError.

std::atomic<bool> gmshBusy{false};

class GmshSession {
 public:
  explicit GmshSession(std::string file) : file_(std::move(file)) {
    bool expected = false;
    if (!gmshBusy.compare_exchange_strong(expected, true))
      throw GeometryError(file_ +
                          ": gmsh is in use by another meshBody call (it is one global state: "
                          "one call at a time)");
    // gmsh::initialize sets the process's locale from the environment (LC_NUMERIC "C") and the
    // OpenMP thread count to 1 (General.NumThreads); both are put back by the destructor.
    if (const char* locale = std::setlocale(LC_ALL, nullptr)) locale_ = locale;
#ifdef _OPENMP
    threads_ = omp_get_max_threads();
#endif
    try {
      gmsh::initialize(0, nullptr, /*readConfigFiles=*/false);
      initialized_ = true;
      gmsh::option::setNumber("General.Terminal", 0);
      gmsh::option::setNumber("General.Verbosity", 2);  // errors and warnings
      // gmsh 4.8 throws its errors by default (AbortOnError 2), also from inside its OpenMP
      // regions (surface meshing), where a throw ends the process: errors are only logged, and
      // run() throws when a call logged one.
      gmsh::option::setNumber("General.AbortOnError", 0);
      gmsh::logger::start();
    } catch (...) {
      release();
      throw GeometryError(file_ + ": gmsh cannot be initialised");
    }
  }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;
  ~GmshSession() {
    release();
  }

  const std::string& file() const {
    return file_;
  }

  // Runs f (gmsh calls); a gmsh failure becomes GeometryError "<file>: <what> (gmsh: <errors>)".
  template <class F>
  void run(const std::string& what, F&& f) {
    try {
      f();
    } catch (const GeometryError&) {
      throw;
    } catch (...) {
      throw GeometryError(file_ + ": " + what + " (gmsh: " + errorText(std::current_exception()) +
                          ")");
    }
    if (const std::string logged = loggedErrors(); !logged.empty())
      throw GeometryError(file_ + ": " + what + " (gmsh: " + logged + ")");
  }

  // The errors gmsh logged since the last look, "; "-separated.
  std::string loggedErrors() {
    std::string text;
    std::vector<std::string> log;
    try {
      gmsh::logger::get(log);
    } catch (...) {
    }
    for (std::size_t i = logSeen_; i < log.size(); ++i) {
      std::string_view line = log[i];
      if (line.rfind("Error", 0) != 0) continue;
      if (const auto colon = line.find(": "); colon != line.npos) line.remove_prefix(colon + 2);
      if (!text.empty()) text += "; ";
      text += line;
    }
    logSeen_ = log.size();
    return text;
  }

  // The errors gmsh logged, or the exception's text.
  std::string errorText(std::exception_ptr failure) {
    std::string text = loggedErrors();
    if (text.empty()) {
      try {
        std::rethrow_exception(failure);
      } catch (const std::string& s) {
        text = s;
      } catch (const char* s) {
        text = s;
      } catch (const std::exception& e) {
        text = e.what();
      } catch (...) {
        text = "unknown error";
      }
    }
    return text.empty() ? "no message" : text;
  }

 private:
  void release() {
    if (initialized_) {
      try {
        gmsh::logger::stop();
      } catch (...) {
      }
      try {
        gmsh::finalize();
      } catch (...) {
      }
      initialized_ = false;
    }
    if (!locale_.empty()) std::setlocale(LC_ALL, locale_.c_str());
#ifdef _OPENMP
    if (threads_ > 0) omp_set_num_threads(threads_);
#endif
    gmshBusy = false;
  }

  std::string file_;
  std::string locale_;
  int threads_ = 0;
  bool initialized_ = false;
  std::size_t logSeen_ = 0;
};

// ---------------------------------------------------------------------------------------------
// Files.

enum class FileKind { Geo, Cad, Stl, Msh };

constexpr std::string_view kKnownExtensions = ".geo, .step, .stp, .brep, .stl, .msh";

std::string extensionOf(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

FileKind fileKind(const std::string& path) {
  const std::string extension = extensionOf(path);
  if (extension == ".geo") return FileKind::Geo;
  if (extension == ".step" || extension == ".stp" || extension == ".brep") return FileKind::Cad;
  if (extension == ".stl") {
    // gmsh 4.8 reads a file as STL by its extension, in lower or upper case only.
    const std::string exact = std::filesystem::path(path).extension().string();
    if (exact != ".stl" && exact != ".STL")
      throw GeometryError(path +
                          ": gmsh reads STL files by the extension .stl or .STL only, not '" +
                          exact + "': rename the file");
    return FileKind::Stl;
  }
  if (extension == ".msh") return FileKind::Msh;
  throw GeometryError(path + ": unknown file kind '" + extension +
                      "' (known: " + std::string(kKnownExtensions) + ")");
}

void requireReadable(const std::string& path) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (!std::filesystem::exists(status))
    throw GeometryError(path + ": cannot read the file: it does not exist");
  if (!std::filesystem::is_regular_file(status))
    throw GeometryError(path + ": cannot read the file: not a regular file");
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw GeometryError(path + ": cannot read the file: it cannot be opened");
}

// ---------------------------------------------------------------------------------------------
// Nodes and elements.

// Coordinates by gmsh node tag (dense tags in a vector, sparse ones in a hash map).
class NodeTable {
 public:
  void load() {
    Tags tags;
    std::vector<double> coord, parametric;
    gmsh::model::mesh::getNodes(tags, coord, parametric, -1, -1, false, false);
    const std::size_t maxTag = tags.empty() ? 0 : *std::max_element(tags.begin(), tags.end());
    dense_ = maxTag <= 4 * tags.size() + 1024;
    coord_ = std::move(coord);
    if (dense_) {
      slot_.assign(maxTag + 1, kNone);
      for (std::size_t i = 0; i < tags.size(); ++i)
        slot_[tags[i]] = i;
    } else {
      for (std::size_t i = 0; i < tags.size(); ++i)
        sparse_[tags[i]] = i;
    }
  }
  Vec3 operator()(std::size_t tag) const {
    std::size_t i = kNone;
    if (dense_) {
      if (tag < slot_.size()) i = slot_[tag];
    } else if (const auto it = sparse_.find(tag); it != sparse_.end()) {
      i = it->second;
    }
    if (i == kNone) throw GeometryError("gmsh node " + std::to_string(tag) + " has no coordinates");
    return Vec3(coord_[3 * i], coord_[3 * i + 1], coord_[3 * i + 2]);
  }

 private:
  static constexpr std::size_t kNone = ~std::size_t{0};
  bool dense_ = true;
  std::vector<double> coord_;
  std::vector<std::size_t> slot_;
  std::unordered_map<std::size_t, std::size_t> sparse_;
};

// One element type's integration data: quadrature points, weights, the Lagrange gradients of
// all its nodes and the hats of its corners at those points (and, for the moments, the
// Lagrange values of all its nodes: the point's position).
struct ElementRule {
  int dim = 0, order = 0, nodes = 0, corners = 0;
  std::string name;
  std::vector<double> weight;
  std::vector<double> grad;     // [point][node][3]
  std::vector<double> hat;      // [point][corner]
  std::vector<double> value;    // [point][node], moments only
  std::vector<double> nodeHat;  // [node][corner]: the corners' linear hats at each node
  std::size_t points() const { return weight.size(); }
};

// What a rule integrates: a D-element's volume (hat times det J), its moments (the same times
// a quadratic in x, of degree 2 order in the reference coordinates; on a straight-sided simplex,
// whose map is affine, degree 3), or a facet's area.
enum class RuleUse { Volume, Moments, StraightMoments, Facet };

std::string familyName(int dim, int corners) {
  if (dim == 1 && corners == 2) return "Line";
  if (dim == 2 && corners == 3) return "Triangle";
  if (dim == 2 && corners == 4) return "Quadrangle";
  if (dim == 3 && corners == 4) return "Tetrahedron";
  if (dim == 3 && corners == 8) return "Hexahedron";
  if (dim == 3 && corners == 6) return "Prism";
  if (dim == 3 && corners == 5) return "Pyramid";
  return {};
}

// The quadrature rule: exact for the volume integrand of elements of geometric order <= 2
// (simplices: hat (degree 1) times det J (degree dim (order - 1)); tensor elements per variable:
// dim * order), and of degree 2 order + 4 on facets, whose area element (a square root on curved
// facets) is not a polynomial. gmsh's "GaussN" rules with a negative weight (4.8: tetrahedra 4,
// 7, 8, 10; triangles 7) are skipped for the next one.
ElementRule makeRule(int type, RuleUse use) {
  const bool facet = use == RuleUse::Facet;
  ElementRule rule;
  std::vector<double> local;
  gmsh::model::mesh::getElementProperties(type, rule.name, rule.dim, rule.order, rule.nodes, local,
                                          rule.corners);
  const std::string family = familyName(rule.dim, rule.corners);
  if (family.empty()) throw GeometryError("unsupported element type '" + rule.name + "'");
  int degree;
  if (facet)
    degree = 2 * rule.order + 4;
  else if (family == "Triangle" || family == "Tetrahedron")
    degree = rule.dim * (rule.order - 1) + 1;
  else
    degree = rule.dim * rule.order + 1;
  if (use == RuleUse::Moments) degree += 2 * rule.order;
  if (use == RuleUse::StraightMoments) degree = 3;
  degree = std::max(degree, 4);  // gmsh's tensor rules below Gauss4 are not Gauss products
  std::vector<double> points;
  for (;; ++degree) {
    gmsh::model::mesh::getIntegrationPoints(type, "Gauss" + std::to_string(degree), points,
                                            rule.weight);
    if (std::all_of(rule.weight.begin(), rule.weight.end(), [](double w) { return w > 0; })) break;
    if (degree > 30) throw GeometryError("no positive quadrature rule for '" + rule.name + "'");
  }
  int components = 0, orientations = 0;
  gmsh::model::mesh::getBasisFunctions(type, points, "GradLagrange", components, rule.grad,
                                       orientations);
  const int linear = gmsh::model::mesh::getElementType(family, 1);
  gmsh::model::mesh::getBasisFunctions(linear, points, "Lagrange", components, rule.hat,
                                       orientations);
  if (use == RuleUse::Moments || use == RuleUse::StraightMoments)
    gmsh::model::mesh::getBasisFunctions(type, points, "Lagrange", components, rule.value,
                                         orientations);
  gmsh::model::mesh::getBasisFunctions(linear, local, "Lagrange", components, rule.nodeHat,
                                       orientations);
  return rule;
}

// A simplex whose higher-order nodes sit where its corners' linear map puts them (all of a
// curved mesh's elements but those at curved boundaries): its map is affine.
bool straightSimplex(const ElementRule& rule, const std::vector<Vec3>& x) {
  if (rule.corners != rule.dim + 1) return false;
  const double tolerance = 1e-10 * (x[1] - x[0]).norm();
  for (int a = rule.corners; a < rule.nodes; ++a) {
    Vec3 linear = Vec3::Zero();
    for (int c = 0; c < rule.corners; ++c)
      linear += rule.nodeHat[a * rule.corners + c] * x[c];
    if (!((linear - x[a]).norm() <= tolerance)) return false;
  }
  return true;
}

class RuleCache {
 public:
  const ElementRule& operator()(int type, RuleUse use) {
    const auto key = std::make_pair(type, use);
    auto it = rules_.find(key);
    if (it == rules_.end()) it = rules_.emplace(key, makeRule(type, use)).first;
    return it->second;
  }

 private:
  std::map<std::pair<int, RuleUse>, ElementRule> rules_;
};

// The Jacobian columns dx/du_k at one quadrature point of an element with nodes x.
inline void jacobian(const ElementRule& rule, std::size_t point, const std::vector<Vec3>& x,
                     Vec3 (&column)[3]) {
  column[0].setZero();
  column[1].setZero();
  column[2].setZero();
  const double* g = &rule.grad[3 * rule.nodes * point];
  for (int n = 0; n < rule.nodes; ++n)
    for (int k = 0; k < rule.dim; ++k)
      column[k] += g[3 * n + k] * x[n];
}

// The signed measure density of a D-element (2D: in the z = 0 plane).
template <int D>
double signedDensity(const Vec3 (&c)[3]) {
  if constexpr (D == 2)
    return c[0].x() * c[1].y() - c[0].y() * c[1].x();
  else
    return c[0].dot(c[1].cross(c[2]));
}

// The measure density of a facet (3D: area, 2D: length).
inline double facetDensity(int dim, const Vec3 (&c)[3]) {
  return dim == 2 ? c[0].cross(c[1]).norm() : c[0].norm();
}

struct ElementBlock {  // the elements of one type on one entity
  int type = 0;
  Tags nodes;  // [element][node]
};

std::vector<ElementBlock> elementBlocks(int dim, int tag) {
  std::vector<int> types;
  std::vector<Tags> elementTags, nodeTags;
  gmsh::model::mesh::getElements(types, elementTags, nodeTags, dim, tag);
  std::vector<ElementBlock> blocks;
  for (std::size_t i = 0; i < types.size(); ++i)
    if (!elementTags[i].empty()) blocks.push_back({types[i], std::move(nodeTags[i])});
  return blocks;
}

template <int D>
Vec<D> head(const Vec3& x) {
  return x.head<D>();
}

// ---------------------------------------------------------------------------------------------
// Model preparation per file kind.

// Counts the triangle edges of the STL surface: every edge of a closed manifold surface bounds
// exactly two triangles.
void requireClosedSurface(GmshSession& session) {
  std::map<std::pair<std::size_t, std::size_t>, int> uses;
  std::size_t triangles = 0;
  session.run("reading the STL triangles", [&] {
    for (const auto& block : elementBlocks(2, -1)) {
      std::string name;
      int dim, order, nodes, corners;
      std::vector<double> local;
      gmsh::model::mesh::getElementProperties(block.type, name, dim, order, nodes, local, corners);
      for (std::size_t e = 0; e < block.nodes.size() / nodes; ++e) {
        ++triangles;
        for (int a = 0; a < corners; ++a) {
          std::size_t p = block.nodes[e * nodes + a],
                      q = block.nodes[e * nodes + (a + 1) % corners];
          ++uses[std::minmax(p, q)];
        }
      }
    }
  });
  if (triangles == 0)
    throw GeometryError(session.file() + ": no triangles in the STL file (empty or not an STL)");
  std::size_t open = 0, nonManifold = 0;
  std::pair<std::size_t, std::size_t> example{0, 0};
  for (const auto& [edge, count] : uses) {
    if (count == 1 && open++ == 0) example = edge;
    if (count > 2) ++nonManifold;
  }
  if (open) {
    std::vector<double> x, parametric;
    gmsh::model::mesh::getNode(example.first, x, parametric);
    throw GeometryError(session.file() + ": the STL surface is not closed: " +
                        std::to_string(open) + " triangle edges bound only one triangle (one at " +
                        pointText<3>(Vec3(x[0], x[1], x[2])) + ")");
  }
  if (nonManifold)
    throw GeometryError(session.file() + ": the STL surface is not a closed manifold: " +
                        std::to_string(nonManifold) + " edges bound more than two triangles");
}

void setMeshOptions(int dim, double size, const MeshOptions& options) {
  gmsh::option::setNumber("Mesh.MeshSizeMax", size);
  gmsh::option::setNumber("Mesh.MeshSizeMin", options.minSizeFactor * size);
  gmsh::option::setNumber("Mesh.SecondOrderLinear", 0);  // order-2 nodes on the geometry
  if (dim == 2) {
    if (options.recombine) gmsh::option::setNumber("Mesh.RecombineAll", 1);
    if (options.algorithm != 0) gmsh::option::setNumber("Mesh.Algorithm", options.algorithm);
  } else if (options.algorithm != 0) {
    gmsh::option::setNumber("Mesh.Algorithm3D", options.algorithm);
  }
}

// gmsh 4.8's Frontal-Delaunay for quads (Mesh.Algorithm 8) dies of a segmentation fault on
// every surface (even a square, from the gmsh program too): refuse it, whoever asked for it.
void refuseCrashingAlgorithm(GmshSession& session) {
  double algorithm = 0;
  std::string version;
  session.run("reading the mesh options", [&] {
    gmsh::option::getNumber("Mesh.Algorithm", algorithm);
    gmsh::option::getString("General.Version", version);
  });
  if (algorithm == 8 && version.rfind("4.8.", 0) == 0)
    throw GeometryError(session.file() + ": Mesh.Algorithm 8 (Frontal-Delaunay for quads) " +
                        "crashes gmsh " + version + ": choose another 2D algorithm");
}

template <int D>
void requireDimension(GmshSession& session) {
  gmsh::vectorpair entities;
  int modelDim = -1;
  session.run("reading the model", [&] {
    modelDim = gmsh::model::getDimension();
    gmsh::model::getEntities(entities, D);
  });
  if (D == 2 && modelDim == 3)
    throw GeometryError(session.file() +
                        ": a 3D model (it has volumes) given to a 2D body: a 2D body is a "
                        "surface model in the z = 0 plane");
  if (entities.empty()) {
    if (D == 3 && modelDim == 2)
      throw GeometryError(session.file() +
                          ": a 2D model (surfaces, no volume) given to a 3D body: the solid "
                          "needs a volume");
    throw GeometryError(session.file() + ": empty solid: the model has no " +
                        (D == 3 ? "volume" : "surface") + " (" + std::to_string(D) +
                        "-dimensional entity)");
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------

template <int D>
MeshedBody<D> meshBody(const std::string& path, double size, const MeshOptions& options) {
  const FileKind kind = fileKind(path);
  requireReadable(path);
  if (kind != FileKind::Msh && !(std::isfinite(size) && size > 0))
    throw GeometryError(path + ": the mesh size must be positive and finite, not " +
                        numberText(size));
  if (!(options.minSizeFactor > 0 && options.minSizeFactor <= 1))
    throw GeometryError(path + ": MeshOptions::minSizeFactor must lie in (0, 1], not " +
                        numberText(options.minSizeFactor));
  if (kind == FileKind::Stl && D == 2)
    throw GeometryError(path + ": an STL surface encloses a volume: it cannot be a 2D body");

  GmshSession session(path);
  if (!options.cadUnit.empty())
    session.run("setting the CAD unit '" + options.cadUnit + "'",
                [&] { gmsh::option::setString("Geometry.OCCTargetUnit", options.cadUnit); });
  session.run("gmsh cannot read the file", [&] {
    if (kind == FileKind::Cad) {
      // gmsh::open picks the reader by the extension's exact case (4.8 takes .step, .STEP,
      // .stp, .STP, .brep, not .BREP or .Stp): the OpenCASCADE import is told the format.
      gmsh::vectorpair imported;
      gmsh::model::occ::importShapes(path, imported, true,
                                     extensionOf(path) == ".brep" ? "brep" : "step");
      gmsh::model::occ::synchronize();
    } else {
      gmsh::open(path);  // .geo by default, .msh by its content, .stl by its extension
    }
  });

  MeshedBody<D> body;
  if (kind == FileKind::Stl) {
    requireClosedSurface(session);
    session.run("gmsh cannot make a volume of the STL surface", [&] {
      // Patches split at 40 degrees (sharp edges become curves), parametrisable for remeshing.
      gmsh::model::mesh::classifySurfaces(40 * std::numbers::pi / 180, true, true,
                                          std::numbers::pi);
      gmsh::model::mesh::createGeometry();
      gmsh::vectorpair surfaces;
      gmsh::model::getEntities(surfaces, 2);
      std::vector<int> tags;
      for (const auto& s : surfaces)
        tags.push_back(s.second);
      const int loop = gmsh::model::geo::addSurfaceLoop(tags);
      gmsh::model::geo::addVolume({loop});
      gmsh::model::geo::synchronize();
    });
  }
  requireDimension<D>(session);

  if (kind == FileKind::Msh) {
    gmsh::vectorpair entities;
    std::size_t count = 0;
    session.run("reading the mesh", [&] {
      gmsh::model::getEntities(entities, D);
      for (const auto& [dim, tag] : entities)
        for (const auto& block : elementBlocks(dim, tag))
          count += block.nodes.size();
    });
    if (count == 0)
      throw GeometryError(path + ": empty solid: the mesh has no " +
                          (D == 3 ? "volume" : "surface") + " elements");
  } else {
    const std::string failure =
        kind == FileKind::Stl
            ? "meshing failed: gmsh cannot fill the STL surface with a volume mesh (a "
              "self-intersecting surface?)"
            : "meshing failed (a self-intersecting or otherwise invalid geometry?)";
    session.run(failure, [&] {
      // A .geo script may have meshed already; the STL's triangles are its surfaces' geometry.
      if (kind != FileKind::Stl) gmsh::model::mesh::clear();
      setMeshOptions(D, size, options);
      // An STL's geometry is its flat triangles: the order-2 nodes stay on the straight edges.
      // Projected onto the triangles' reparametrised patches they kink across the triangles'
      // edges and invert elements wherever the mesh is not much finer than the triangles.
      if (kind == FileKind::Stl) gmsh::option::setNumber("Mesh.SecondOrderLinear", 1);
    });
    refuseCrashingAlgorithm(session);
    session.run(failure, [&] { gmsh::model::mesh::generate(D); });
    session.run("raising the mesh to order 2 failed", [&] { gmsh::model::mesh::setOrder(2); });
    session.run("reading the CAD measure", [&] {
      gmsh::vectorpair occEntities;
      gmsh::model::occ::getEntities(occEntities, D);
      if (occEntities.empty()) return;
      double total = 0;
      for (const auto& [dim, tag] : occEntities) {
        double mass = 0;
        gmsh::model::occ::getMass(dim, tag, mass);
        total += mass;
      }
      body.exactMeasure = total;
    });
  }

  // The D-elements, entity by entity.
  NodeTable nodes;
  gmsh::vectorpair entities;
  std::vector<std::vector<ElementBlock>> blocks;
  session.run("reading the mesh", [&] {
    nodes.load();
    gmsh::model::getEntities(entities, D);
    for (const auto& [dim, tag] : entities)
      blocks.push_back(elementBlocks(dim, tag));
  });

  RuleCache rules;
  auto rule = [&](int type, RuleUse use) -> const ElementRule& {
    const ElementRule* r = nullptr;
    session.run("reading the element basis", [&] { r = &rules(type, use); });
    return *r;
  };

  // Particles: the corner nodes of the D-elements, in increasing tag.
  std::vector<std::size_t> cornerTags;
  std::size_t elementCount = 0;
  int maxOrder = 0;
  for (const auto& entityBlocks : blocks)
    for (const auto& block : entityBlocks) {
      const ElementRule& r = rule(block.type, RuleUse::Volume);
      maxOrder = std::max(maxOrder, r.order);
      const std::size_t n = block.nodes.size() / r.nodes;
      elementCount += n;
      for (std::size_t e = 0; e < n; ++e)
        for (int a = 0; a < r.corners; ++a)
          cornerTags.push_back(block.nodes[e * r.nodes + a]);
    }
  if (elementCount == 0)
    throw GeometryError(path + ": empty solid: the mesh has no " + (D == 3 ? "volume" : "surface") +
                        " elements");
  body.curved = maxOrder >= 2;
  std::sort(cornerTags.begin(), cornerTags.end());
  cornerTags.erase(std::unique(cornerTags.begin(), cornerTags.end()), cornerTags.end());
  std::unordered_map<std::size_t, Index> particleOf;
  particleOf.reserve(cornerTags.size());
  body.position.reserve(cornerTags.size());
  double extent = 0;
  for (const std::size_t tag : cornerTags) {
    const Vec3 x = nodes(tag);
    particleOf.emplace(tag, static_cast<Index>(body.position.size()));
    body.position.push_back(head<D>(x));
    extent = std::max(extent, x.head<D>().cwiseAbs().maxCoeff());
  }
  body.volume.assign(body.position.size(), 0.0);

  // Volumes and cells; in 2D every node of the D-elements must lie in the z = 0 plane. The
  // elements of one entity share one orientation, the sign of their total (a 2D surface may face
  // -z): an element against it is inverted.
  const double planeTolerance = 1e-9 * std::max(extent, 1e-300);
  std::vector<Vec3> x;
  std::vector<std::pair<Index, double>> contribution;  // one entity's (particle, signed volume)
  // and its signed moments int lambda_I (x - X_I) dV, int lambda_I (x - X_I)(x - X_I)^T dV
  std::vector<std::pair<Vec<D>, Mat<D>>> momentContribution;
  std::vector<double> elementSigned;
  std::vector<Vec<D>> m1(body.position.size(), Vec<D>::Zero());
  std::vector<Mat<D>> M2(body.position.size(), Mat<D>::Zero());
  body.firstMoment.setZero();
  body.secondMoment.setZero();
  for (std::size_t k = 0; k < entities.size(); ++k) {
    contribution.clear();
    momentContribution.clear();
    elementSigned.clear();
    double entitySigned = 0;
    Vec<D> entityFirst = Vec<D>::Zero();
    Mat<D> entitySecond = Mat<D>::Zero();
    for (const auto& block : blocks[k]) {
      const ElementRule& r = rule(block.type, RuleUse::Volume);
      const ElementRule& curvedRule = rule(block.type, RuleUse::Moments);
      const ElementRule& straightRule = rule(block.type, RuleUse::StraightMoments);
      const std::size_t n = block.nodes.size() / r.nodes;
      for (std::size_t e = 0; e < n; ++e) {
        const std::size_t* tags = &block.nodes[e * r.nodes];
        x.resize(r.nodes);
        for (int a = 0; a < r.nodes; ++a) {
          x[a] = nodes(tags[a]);
          if (D == 2 && !(std::abs(x[a].z()) <= planeTolerance))
            throw GeometryError(path + ": the 2D model is not in the z = 0 plane (a node at " +
                                pointText<3>(x[a]) + ")");
        }
        const std::size_t first = contribution.size();
        for (int a = 0; a < r.corners; ++a) {
          const Index p = particleOf.at(tags[a]);
          contribution.emplace_back(p, 0.0);
          body.cellNode.push_back(p);
        }
        body.cellStart.push_back(static_cast<Index>(body.cellNode.size()));
        double total = 0;
        for (std::size_t q = 0; q < r.points(); ++q) {
          Vec3 c[3];
          jacobian(r, q, x, c);
          const double dv = signedDensity<D>(c) * r.weight[q];
          total += dv;
          for (int a = 0; a < r.corners; ++a)
            contribution[first + a].second += r.hat[q * r.corners + a] * dv;
        }
        // The moments, on the same geometry with a rule of 2 order degrees more (exact for an
        // affine simplex at degree 3: most of a mesh, at a fraction of the points).
        const ElementRule& rm = straightSimplex(r, x) ? straightRule : curvedRule;
        momentContribution.resize(contribution.size(), {Vec<D>::Zero(), Mat<D>::Zero()});
        for (std::size_t q = 0; q < rm.points(); ++q) {
          Vec3 c[3];
          jacobian(rm, q, x, c);
          const double dv = signedDensity<D>(c) * rm.weight[q];
          Vec3 xq = Vec3::Zero();
          for (int a = 0; a < rm.nodes; ++a)
            xq += rm.value[q * rm.nodes + a] * x[a];
          const Vec<D> X = head<D>(xq);
          entityFirst += dv * X;
          entitySecond += dv * X * X.transpose();
          for (int a = 0; a < rm.corners; ++a) {
            const Vec<D> d = X - body.position[contribution[first + a].first];
            const double w = rm.hat[q * rm.corners + a] * dv;
            momentContribution[first + a].first += w * d;
            momentContribution[first + a].second += w * d * d.transpose();
          }
        }
        elementSigned.push_back(total);
        entitySigned += total;
      }
    }
    const double sign = entitySigned < 0 ? -1.0 : 1.0;
    for (const double v : elementSigned)
      if (!(sign * v > 0))
        throw GeometryError(path + ": an inverted element (volume " + numberText(sign * v) +
                            " against its neighbours' orientation) in " +
                            (D == 3 ? "volume " : "surface ") + std::to_string(entities[k].second));
    for (std::size_t c = 0; c < contribution.size(); ++c) {
      const Index p = contribution[c].first;
      body.volume[p] += sign * contribution[c].second;
      m1[p] += sign * momentContribution[c].first;
      M2[p] += sign * momentContribution[c].second;
    }
    body.measure += sign * entitySigned;
    body.firstMoment += sign * entityFirst;
    body.secondMoment += sign * entitySecond;
  }
  for (std::size_t i = 0; i < body.volume.size(); ++i)
    if (!(body.volume[i] > 0))
      throw GeometryError(path + ": non-positive volume " + numberText(body.volume[i]) +
                          " of the node at " + pointText<D>(body.position[i]) +
                          " (an inverted element there)");
  body.offset.resize(body.position.size());
  body.spread.resize(body.position.size());
  for (std::size_t i = 0; i < body.volume.size(); ++i) {
    body.offset[i] = m1[i] / body.volume[i];
    body.spread[i] = M2[i] / body.volume[i];
  }

  // Physical groups.
  gmsh::vectorpair groups;
  session.run("reading the physical groups", [&] { gmsh::model::getPhysicalGroups(groups); });
  std::vector<std::vector<Index>> cellsOf;  // the D-cells at each particle (for orientation)
  for (const auto& [dim, group] : groups) {
    if (dim != D && dim != D - 1) continue;
    std::string name;
    std::vector<int> groupEntities;
    session.run("reading the physical groups", [&] {
      gmsh::model::getPhysicalName(dim, group, name);
      gmsh::model::getEntitiesForPhysicalGroup(dim, group, groupEntities);
    });
    if (name.empty()) name = std::to_string(group);
    std::vector<std::vector<ElementBlock>> groupBlocks;
    session.run("reading the physical groups", [&] {
      for (const int tag : groupEntities)
        groupBlocks.push_back(elementBlocks(dim, tag));
    });

    if (dim == D) {
      std::vector<Index>& list = body.volumes[name];
      for (const auto& entityBlocks : groupBlocks)
        for (const auto& block : entityBlocks) {
          const ElementRule& r = rule(block.type, RuleUse::Volume);
          for (std::size_t e = 0; e < block.nodes.size() / r.nodes; ++e)
            for (int a = 0; a < r.corners; ++a)
              list.push_back(particleOf.at(block.nodes[e * r.nodes + a]));
        }
      std::sort(list.begin(), list.end());
      list.erase(std::unique(list.begin(), list.end()), list.end());
      continue;
    }

    if (cellsOf.empty()) {
      cellsOf.resize(body.position.size());
      for (std::size_t c = 0; c + 1 < body.cellStart.size(); ++c)
        for (Index i = body.cellStart[c]; i < body.cellStart[c + 1]; ++i)
          cellsOf[body.cellNode[i]].push_back(static_cast<Index>(c));
    }
    typename MeshedBody<D>::Surface surface;
    std::map<Index, double> areaOf;
    std::map<Index, Vec<D>> areaVectorOf;
    for (const auto& entityBlocks : groupBlocks)
      for (const auto& block : entityBlocks) {
        const ElementRule& r = rule(block.type, RuleUse::Facet);
        const std::size_t n = block.nodes.size() / r.nodes;
        for (std::size_t e = 0; e < n; ++e) {
          std::vector<Index> corner(r.corners);
          for (int a = 0; a < r.corners; ++a) {
            const auto it = particleOf.find(block.nodes[e * r.nodes + a]);
            if (it == particleOf.end())
              throw GeometryError(path + ": the physical " + (D == 3 ? "surface '" : "curve '") +
                                  name + "' is not on the solid's boundary (a node at " +
                                  pointText<3>(nodes(block.nodes[e * r.nodes + a])) +
                                  " belongs to no " + (D == 3 ? "volume" : "surface") +
                                  " element)");
            corner[a] = it->second;
          }
          // The adjacent D-cell: one holding all the facet's corners.
          Index cell = -1;
          for (const Index c : cellsOf[corner[0]]) {
            const auto begin = body.cellNode.begin() + body.cellStart[c];
            const auto end = body.cellNode.begin() + body.cellStart[c + 1];
            if (std::all_of(corner.begin(), corner.end(),
                            [&](Index p) { return std::find(begin, end, p) != end; })) {
              cell = c;
              break;
            }
          }
          if (cell < 0)
            throw GeometryError(path + ": the physical " + (D == 3 ? "surface '" : "curve '") +
                                name + "' has a facet on no " + (D == 3 ? "volume" : "surface") +
                                " element (near " + pointText<D>(body.position[corner[0]]) + ")");
          Vec<D> cellCentre = Vec<D>::Zero(), facetCentre = Vec<D>::Zero();
          for (Index i = body.cellStart[cell]; i < body.cellStart[cell + 1]; ++i)
            cellCentre += body.position[body.cellNode[i]];
          cellCentre /= body.cellStart[cell + 1] - body.cellStart[cell];
          for (const Index p : corner)
            facetCentre += body.position[p];
          facetCentre /= static_cast<double>(corner.size());
          const Vec<D> out = facetCentre - cellCentre;
          auto linearNormal = [&](const std::array<Index, D>& f) {
            const Vec<D> a = body.position[f[1]] - body.position[f[0]];
            if constexpr (D == 2)
              return Vec<D>(a.y(), -a.x());
            else
              return Vec<D>(a.cross(body.position[f[2]] - body.position[f[0]]));
          };
          auto addFacet = [&](std::array<Index, D> f) {
            if (linearNormal(f).dot(out) < 0) std::swap(f[0], f[1]);
            surface.facets.push_back(f);
          };
          // gmsh's corner order gives the curved facet's normal below (3D: dx/du x dx/dv, 2D:
          // dx/du turned by -90 degrees) the orientation of the linear one: flip it if inward.
          std::array<Index, D> gmshOrder;
          std::copy_n(corner.begin(), D, gmshOrder.begin());
          const double outward = linearNormal(gmshOrder).dot(out) < 0 ? -1.0 : 1.0;
          if constexpr (D == 2) {
            addFacet({corner[0], corner[1]});
          } else {
            addFacet({corner[0], corner[1], corner[2]});
            if (corner.size() == 4) addFacet({corner[0], corner[2], corner[3]});
          }
          // Areas on the curved facet.
          x.resize(r.nodes);
          for (int a = 0; a < r.nodes; ++a)
            x[a] = nodes(block.nodes[e * r.nodes + a]);
          std::vector<double> nodeArea(r.corners, 0.0);
          std::vector<Vec<D>> nodeAreaVector(r.corners, Vec<D>::Zero());
          for (std::size_t q = 0; q < r.points(); ++q) {
            Vec3 c[3];
            jacobian(r, q, x, c);
            const double da = facetDensity(r.dim, c) * r.weight[q];
            Vec<D> nda;
            if constexpr (D == 2)
              nda = Vec<D>(c[0].y(), -c[0].x());
            else
              nda = c[0].cross(c[1]);
            nda *= outward * r.weight[q];
            surface.measure += da;
            for (int a = 0; a < r.corners; ++a) {
              nodeArea[a] += r.hat[q * r.corners + a] * da;
              nodeAreaVector[a] += r.hat[q * r.corners + a] * nda;
            }
          }
          for (int a = 0; a < r.corners; ++a) {
            areaOf[corner[a]] += nodeArea[a];
            // (Eigen's vectors start uninitialised: insert a zero, then add.)
            areaVectorOf.try_emplace(corner[a], Vec<D>::Zero()).first->second += nodeAreaVector[a];
          }
        }
      }
    for (const auto& [p, a] : areaOf) {
      surface.nodes.push_back(p);
      surface.area.push_back(a);
      surface.areaVector.push_back(areaVectorOf.at(p));
    }
    body.surfaces[name] = std::move(surface);
  }
  return body;
}

template MeshedBody<2> meshBody<2>(const std::string&, double, const MeshOptions&);
template MeshedBody<3> meshBody<3>(const std::string&, double, const MeshOptions&);

}  // namespace tlsph
