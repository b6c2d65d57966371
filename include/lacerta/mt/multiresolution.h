/**
 * @file
 * Multiresolution in a scene: the MT built or loaded, the level of detail following
 * the tool, and the state of the particles carried from one level to the next.
 */
#pragma once

#include <lacerta/cut/cut_record.h>
#include <lacerta/cut/geometry.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/mt/coarse_stiffness.h>
#include <lacerta/mt/homogenized_stiffness.h>
#include <lacerta/mt/lod.h>
#include <lacerta/mt/lod_query.h>
#include <lacerta/mt/mt_cutter.h>
#include <lacerta/mt/multi_triangulation.h>
#include <lacerta/mt/storage.h>

#include <deal.II/base/parameter_handler.h>

#include <cstdint>
#include <iosfwd>
#include <memory>
#include <vector>

namespace dealii
{
  template <int dim>
  class FunctionParser;
}

namespace lacerta::cut
{
  struct Blade;
}

namespace lacerta
{
  class Archive;
}
namespace lacerta::physics
{
  class ParticleSystem;
  class TopologyUpdate;
} // namespace lacerta::physics
namespace lacerta::mt
{
  /**
   * Owns the MT of a scene's mesh (from the cache or built), the current level of
   * detail and its mesh, and decides when to re-extract: when the focus (a point moving
   * along `Focus path`, or with `Focus follows = tool` following the scalpel's blade) has
   * moved more than `Re-extraction distance` since the last extraction, or every
   * `Re-extraction interval` steps. Only scenes with `Multiresolution/Enabled = true`
   * create one.
   */
  class Multiresolution
  {
  public:
    /// Declares `subsection Multiresolution`.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Whether @p prm enables multiresolution.
    static bool
    enabled(dealii::ParameterHandler &prm);

    /**
     * Builds or loads the MT of @p mesh (whose @p locked vertices are never removed)
     * and extracts the level of detail for the focus at time 0: on the path, or with
     * `Focus follows = tool` at @p blade, the tool's blade at time 0 (an error if there
     * is none).
     */
    Multiresolution(dealii::ParameterHandler        &prm,
                    const mesh::TetMesh             &mesh,
                    const std::vector<unsigned int> &locked,
                    const cut::Blade                *blade);

    ~Multiresolution();

    /**
     * Re-extracts if the focus at time @p time (step @p step) has moved far enough or
     * the interval has passed; returns whether the level of detail changed. With
     * `Focus follows = tool` the focus is at @p blade, the blade where the tool now is.
     * The active mesh does not change yet: apply_change() makes the change.
     */
    bool
    update(double time, unsigned int step, const cut::Blade *blade);

    /**
     * Moves the active mesh and @p system (whose particles are its vertices) to the
     * level of detail the last update() extracted, locally, through @p topology (the
     * same update a cut makes): the fragments that went leave, those that came
     * arrive, the vertices only they held are removed, and the region keeps its mass
     * (TopologyUpdate::conserve_mass()). A vertex that comes gets its
     * state interpolated in the previous level's tetrahedron that contains it
     * (Lod::locate_in_previous(), barycentric coordinates clamped to it, Section 4.2).
     * Particles are renumbered: the last ones move into freed slots and, when the
     * numbering has drifted from the spatial order a new level has, all of them are
     * put back in that order (TopologyUpdate::restore_spatial_order()). Returns the new
     * index of every particle (TopologyUpdate::particle_renumbering()).
     */
    const std::vector<unsigned int> &
    apply_change(physics::TopologyUpdate &topology, physics::ParticleSystem &system);

    /// The cells the last apply_change() removed and added (their sum).
    std::size_t
    last_swapped_cells() const
    {
      return mt_removed.size() + mt_added.size();
    }

    /// The mesh of the current level of detail (vertices numbered compactly).
    const mesh::TetMesh &
    active_mesh() const
    {
      return mesh;
    }

    /**
     * The mesh of the current level of detail, for the Cutter to cut in place. Once
     * cut, its new particles have no MT vertex id (active_vertices() lists the first
     * ones only) until apply_cut() records them; update() must not be called between.
     */
    mesh::TetMesh &
    mesh_to_cut()
    {
      return mesh;
    }

    /**
     * Replays @p records (made by a Cutter on mesh_to_cut(), in order) on the MT
     * (MtCutter): the level of detail's MT version is then the cut mesh itself, which
     * stays the active mesh, its new particles with MT vertex ids, and every later
     * extraction keeps the cut (doc/mt-cutting.md). The MT's vertex index is built at
     * the first call. Returns the MT columns of the paper's Table 2.
     */
    MtCutter::Statistics
    apply_cut(const std::vector<cut::CutRecord> &records);

    /// The MT vertex id of every vertex of active_mesh() (increasing after the first
    /// extraction; local changes renumber vertices into freed slots).
    const std::vector<std::uint32_t> &
    active_vertices() const
    {
      return vertices;
    }

    /**
     * Sets the spring rule of the scene's material (Section 3.2's, or fitted springs)
     * and the coarse cells' stiffness from it (`Coarse stiffness`): with `homogenized`,
     * the one factor on the decimated cells that gives the coarsest mesh the input
     * mesh's energy under uniform strain (homogenized_coarse_scale()); with
     * `condensed`, every coarse fragment's stiffness condensed from the fine mesh
     * (condensed_edge_stiffnesses()).
     */
    void
    set_stiffness_rule(const EdgeStiffnessRule &rule);

    /// Whether the coarse cells' springs differ from the rule (`Coarse stiffness` is
    /// not `rule`): the cells then carry their own stiffnesses (edge_stiffnesses()).
    bool
    has_coarse_stiffness() const
    {
      return coarse_stiffness != CoarseStiffness::rule;
    }

    /**
     * The contributions to its six edges' stiffnesses (local edge order) of the
     * active mesh's cell @p cell (particle ids) that is MT tetrahedron @p t: the rule,
     * times the homogenized factor for a decimated tetrahedron, or condensed; the rule
     * for tetrahedra a cut made.
     */
    std::array<double, 6>
    edge_stiffnesses(std::uint32_t t, const mesh::Tet &cell) const;

    /// edge_stiffnesses() of every cell of active_mesh().
    std::vector<std::array<double, 6>>
    active_cell_stiffnesses() const;

    /// Writes the MT's size, its build or load and the current level of detail.
    void
    print_summary(std::ostream &out, bool test_mode) const;

    /// Writes one line about the last change of the level of detail at @p time, with
    /// the particle system's @p total_mass.
    void
    print_change(std::ostream &out, double time, double total_mass) const;

    /// The Multi-Triangulation.
    const MultiTriangulation &
    multi_triangulation() const
    {
      return mt;
    }

    /**
     * The focus at time @p time: on `Focus path`, or with `Focus follows = tool`
     * focus_of_blade() of @p blade.
     */
    mesh::Point3
    focus(double time, const cut::Blade *blade) const;

    /**
     * Where a blade puts the focus: the middle of the part of the segment inside the
     * bounding box of the mesh at rest, or, if it misses the box, the point of the box
     * nearest to it (where the blade runs parallel to a face, nearest to the middle of
     * the blade's nearest points, to 1/64 of the blade). The blade's world coordinates
     * are taken as rest coordinates, which the level of detail's fine region (a few cells
     * around the focus) tolerates.
     */
    mesh::Point3
    focus_of_blade(const cut::Blade &blade) const;

    /// Writes or reads the state for a checkpoint (see lacerta::Archive).
    void
    serialize(Archive &archive);

  private:
    /// Rebuilds the mesh and the vertex lists from the Lod.
    void
    make_active_mesh();

    /// Enters the mesh vertices from @p first on into `mesh_vertex_of`.
    void
    index_mesh_vertices(std::size_t first);

    /// The active mesh's tetrahedron with the vertices of MT tetrahedron @p t (an
    /// internal error if there is none).
    unsigned int
    mesh_tet_of(std::uint32_t t) const;

    MultiTriangulation                         mt;
    std::unique_ptr<MtCutter>                  mt_cutter;
    CacheReport                                cache;
    std::unique_ptr<Lod>                       lod;
    std::unique_ptr<LodQuery>                  query;
    std::unique_ptr<dealii::FunctionParser<3>> path;
    /// `Coarse stiffness`.
    enum class CoarseStiffness
    {
      rule,
      homogenized,
      condensed
    } coarse_stiffness = CoarseStiffness::rule;
    /// With `homogenized`: the factor, what it matched, and the tetrahedra of the MT
    /// as built (those a cut appends after it take the rule).
    HomogenizedScale homogenized;
    std::uint32_t    built_tets = 0;
    /// The material's spring rule (set_stiffness_rule()).
    EdgeStiffnessRule rule;
    /// Per MT tetrahedron, its edges' condensed stiffness contributions (empty with
    /// `Coarse stiffness = rule`).
    std::vector<std::array<double, 6>> condensed;
    /// `Focus follows = tool`: the focus follows the blade, not the path.
    bool follows_tool = false;
    /// The bounding box of the mesh at rest.
    cut::Box                   box;
    double                     distance = 0;
    unsigned int               interval = 1;
    mesh::Point3               last_focus{};
    unsigned int               last_step = 0;
    mesh::TetMesh              mesh;
    std::vector<std::uint32_t> vertices;
    /// The active mesh's vertex of every MT vertex, invalid_index if inactive.
    std::vector<std::uint32_t> mesh_vertex_of;
    /// Scratch of apply_change().
    std::vector<std::uint32_t>               mt_removed, mt_added;
    std::vector<unsigned int>                removed, held, dead;
    std::vector<mesh::Tet>                   added;
    std::vector<std::array<double, 6>>       added_stiffness;
    std::vector<std::array<unsigned int, 4>> face_ids;
    std::vector<std::uint32_t>               renumbered_vertices;
    std::size_t                              n_kept = 0, n_new = 0;
  };
} // namespace lacerta::mt
