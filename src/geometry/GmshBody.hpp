// A body from a CAD or mesh file, through gmsh: the particles are the corner (primary) nodes of a
// gmsh mesh of the solid, so the boundary is represented by particles lying ON the CAD surface.
// Each particle's volume is the integral of its corner hat function over the mesh, with the
// second-order (curved) geometry, and each physical surface carries its outward-oriented facets
// and per-node areas, likewise integrated on the curved geometry.
//
// File kinds, by extension (case-insensitive):
//   .geo              gmsh script (built-in or OpenCASCADE kernel); meshed at `size`
//   .step .stp .brep  CAD imported through gmsh's OpenCASCADE reader; meshed at `size`
//   .stl              a closed triangulated surface (3D only): classified into patches, a volume
//                     made from the surface loop, then remeshed at `size`
//   .msh              an existing mesh: its D-dimensional elements are taken as they are (not
//                     remeshed, `size` is ignored); a first-order mesh is integrated on its
//                     linear geometry (MeshedBody::curved == false)
//
// gmsh is one global state: meshBody initialises and finalises it around each call, and is not
// reentrant (a second call while one runs, from another thread, throws GeometryError). The
// caller's locale and OpenMP thread count, which gmsh::initialize changes, are put back.
//
// Nothing is written to disk by meshBody or gmsh's meshing, with two exceptions outside our
// control: a .geo script is run as given (a `Save` command in it would write), and Debian's gmsh
// 4.8.4, built with FLTK, rewrites FLTK's preference files at every gmsh::initialize
// (~/.fltk/fltk.org/fltk.prefs, and /etc/fltk/fltk.org/fltk.prefs when run as root; an empty
// 94-byte file, created on first use).
#pragma once

#include <array>
#include <cstddef>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "model/Types.hpp"

namespace tlsph {

// A geometry file that cannot be made into a body; the message names the file and the reason.
class GeometryError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct MeshOptions {
  // 2D: recombine the triangles into quadrangles (gmsh's Mesh.RecombineAll, by its default
  // Blossom matching), a much more regular particle set; a few triangles may remain.
  // 3D: ignored (the volumes stay tetrahedral: gmsh 4.8's all-hex options, subdivision and
  // Recombine3DAll, give poorly shaped or mixed elements).
  bool recombine = false;
  // gmsh's algorithm for the D-dimensional mesh (2D: Mesh.Algorithm, 3D: Mesh.Algorithm3D);
  // 0 leaves gmsh's default (or what the .geo file set). gmsh 4.8's Mesh.Algorithm 8
  // (Frontal-Delaunay for quads) crashes the process, and is refused with a GeometryError.
  int algorithm = 0;
  // The element size is bounded to [minSizeFactor * size, size] (Mesh.MeshSizeMin/Max). The
  // particles are as far apart as the mesh's edges: SPH wants them nearly uniform, yet a feature
  // smaller than `size` (a thin wall, a small hole, a point size set in a .geo) should still get
  // some resolution. Down to half the size, the particle spacing varies by at most a factor of 2.
  double minSizeFactor = 0.5;
  // The length unit STEP and BREP geometry is converted to (gmsh's Geometry.OCCTargetUnit:
  // "M", "CM", "MM", "INCH", ...). Empty: OpenCASCADE's default, millimetres, so that a STEP
  // file written in metres comes in 1000 times larger. Set it to the scene's unit.
  std::string cadUnit;
};

template <int D>  // D = 2: a surface in the z = 0 plane is the plane body; D = 3: a volume
struct MeshedBody {
  static_assert(D == 2 || D == 3);
  // The corner nodes of the D-dimensional elements (no mid-edge nodes, no nodes of
  // lower-dimensional entities that no D-element uses), in increasing gmsh node tag.
  std::vector<Vec<D>> position;
  // V_I = sum_e int_e lambda_I dV: lambda_I the corner's linear (bilinear, trilinear) hat on the
  // reference element, dV from the order-2 geometry (first order for a first-order .msh). Every
  // V_I > 0 (GeometryError otherwise).
  std::vector<double> volume;
  // The moments of each node's hat lambda_I about the node, divided by its volume
  // (model/QuadratureMoments.hpp): offset mu_I = 1/V_I int lambda_I (x - X_I) dV and spread
  // N_I = 1/V_I int lambda_I (x - X_I)(x - X_I)^T dV, on the same geometry as the volumes with a
  // rule exact for them (2 order degrees above the volumes'). A node on the surface has its
  // hat's centroid inside the body (mu_I != 0), and N_I is not a lattice cell's l^2/12 1: the
  // Taylor quadrature term needs both to correct the one-point sum at the nodes.
  std::vector<Vec<D>> offset;
  std::vector<Mat<D>> spread;
  // The mesh's measure (volume; 2D: area) integrated element by element on the same geometry,
  // without the hats: sum of volume equals it by partition of unity (up to rounding).
  double measure = 0;
  // Likewise int x dV and int x x^T dV: sum_I V_I (X_I + mu_I) equals the first, and
  // sum_I V_I (X_I X_I^T + mu_I X_I^T + X_I mu_I^T + N_I) the second.
  Vec<D> firstMoment = Vec<D>::Zero();
  Mat<D> secondMoment = Mat<D>::Zero();
  // The CAD model's measure from OpenCASCADE (occ::getMass of its D-dimensional entities) when
  // the model has OpenCASCADE entities; NaN otherwise (built-in kernel .geo, .stl, .msh).
  double exactMeasure = std::numeric_limits<double>::quiet_NaN();
  // Whether the integration used curved (order >= 2) elements: false for a first-order .msh.
  bool curved = true;
  // The D-elements by their corner particles (compressed rows: cell c has the corners
  // cellNode[cellStart[c] .. cellStart[c + 1]), in gmsh's corner order; 2D: 3 = triangle,
  // 4 = quadrangle).
  std::vector<Index> cellStart{0};
  std::vector<Index> cellNode;

  struct Surface {  // a physical group of dimension D - 1 (3D: surfaces, 2D: curves)
    // The corner particles of each linear facet (3D: triangles, a quadrangle split into two;
    // 2D: segments), ordered so that the facet's normal (3D: (x1 - x0) x (x2 - x0); 2D: x1 - x0
    // turned by -90 degrees) points out of the adjacent D-element. A facet between two elements
    // (an interface inside the solid) points out of the first one gmsh lists.
    std::vector<std::array<Index, D>> facets;
    // Per particle of `nodes`: A_I = int_S lambda_I dA on the curved (order-2) surface.
    std::vector<double> area;
    // Per particle of `nodes`: a_I = int_S lambda_I n dA, n the outward unit normal of the curved
    // surface: the particle's share of the vector area, so that a pressure p puts -p a_I on it
    // and the shares of a closed surface sum to zero (up to rounding).
    std::vector<Vec<D>> areaVector;
    std::vector<Index> nodes;  // the particles on this surface (sorted, unique)
    // The surface's area (2D: length), integrated element by element on the curved geometry;
    // equals the sum of `area` by partition of unity.
    double measure = 0;
  };
  // Physical groups by name (an unnamed group by its tag as text).
  std::map<std::string, Surface> surfaces;
  std::map<std::string, std::vector<Index>> volumes;  // groups of dimension D: particles, sorted
};

// Meshes the file at element size `size` (model units; ignored for .msh) and returns the body.
// Throws GeometryError naming the file and the reason when the file is missing or unreadable,
// of an unknown kind, not a solid of dimension D, open (.stl), not meshable (for instance a
// self-intersecting surface), not in the z = 0 plane (2D), or gives a non-positive node volume.
template <int D>
MeshedBody<D> meshBody(const std::string& path, double size, const MeshOptions& options = {});

extern template MeshedBody<2> meshBody<2>(const std::string&, double, const MeshOptions&);
extern template MeshedBody<3> meshBody<3>(const std::string&, double, const MeshOptions&);

}  // namespace tlsph
