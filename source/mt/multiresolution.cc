#include <lacerta/base/archive.h>
#include <lacerta/base/exceptions.h>
#include <lacerta/base/parameter_utilities.h>
#include <lacerta/base/parsed_function.h>
#include <lacerta/cut/tool.h>
#include <lacerta/mt/coarse_stiffness.h>
#include <lacerta/mt/multiresolution.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/topology_update.h>

#include <deal.II/base/function_parser.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <ostream>

namespace lacerta::mt
{
  void
  Multiresolution::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Multiresolution");
    prm.declare_entry(
      "Enabled",
      "false",
      dealii::Patterns::Bool(),
      "Simulate on a level of detail extracted from a Multi-Triangulation "
      "(Section 4) that follows the focus; without it no MT is built.");
    prm.declare_entry("Cache directory",
                      "mt-cache",
                      dealii::Patterns::Anything(),
                      "Where built MTs are kept, one file per mesh and builder "
                      "parameters (mt-<key>.lmt), with the homogenized coarse "
                      "stiffness of the material beside it (mt-<key>.lmt.homogenized); "
                      "a stale or corrupted file is rebuilt. Empty: always build, never "
                      "write.");
    prm.declare_entry("Focus path",
                      "0; 0; 0",
                      dealii::Patterns::Anything(),
                      "Position of the tool the level of detail follows, as a function "
                      "of t: three expressions separated by ';' [m].");
    prm.declare_entry("Focus follows",
                      "path",
                      dealii::Patterns::Selection("path|tool"),
                      "What the level of detail follows. path: the point of 'Focus "
                      "path' at time t. tool: the scalpel's blade (the scene's tool, or "
                      "the mouse in lacerta-view): the middle of its part inside the "
                      "object's bounding box at rest, or the point of the box nearest "
                      "to it.");
    prm.declare_entry("Re-extraction distance",
                      "0.005",
                      dealii::Patterns::Double(0.0, 1e3),
                      "The level of detail is extracted again when the focus has moved "
                      "more than this since the last extraction [m].");
    prm.declare_entry("Re-extraction interval",
                      "50",
                      dealii::Patterns::Integer(1, 100000000),
                      "... or when this many steps have passed since the last one.");
    prm.declare_entry(
      "Coarse stiffness",
      "homogenized",
      dealii::Patterns::Selection("rule|homogenized|condensed"),
      "The springs of the decimated cells. rule: the rule of 'Material/Spring "
      "stiffness' applied to the coarse cells as to any mesh (Section 3.2's springs "
      "on a decimated mesh are a softer material than on the input mesh, about 10 % "
      "on an irregular one). homogenized: the rule times one factor, found when the "
      "MT is built, that gives the coarsest mesh the input mesh's energy under "
      "uniform strain (boundary displaced affinely, interior relaxed). condensed: "
      "the rule's springs scaled per edge so that each coarse fragment's energies "
      "under uniform strains are those of the fine cells it replaced with the "
      "removed vertex condensed out; measured to make the level of detail softer "
      "than the full mesh, not closer to it (doc/multiresolution.md, 'The material "
      "of a level of detail').");
    LodQueryRegistry::declare_selector(prm,
                                       "Query",
                                       "focus",
                                       "How fine the level of detail must be where.");
    LodQueryRegistry::declare_all_in_subsections(prm);
    prm.enter_subsection("Builder");
    prm.declare_entry(
      "Minimum quality",
      "0.3",
      dealii::Patterns::Double(0.001, 0.9),
      "No decimation step may create a tetrahedron of lower mean-ratio "
      "quality 12 (3V)^(2/3) / sum of squared edges (1 regular, 0 flat). Springs "
      "on flat tetrahedra make a softer material than the fine mesh they stand "
      "for: at 0.1 the first level of detail's static error is up to twice that "
      "at 0.3 (doc/multiresolution.md).");
    prm.declare_entry(
      "Maximum boundary error",
      "0.01",
      dealii::Patterns::Double(0.0, 1.0),
      "Largest approximate Hausdorff distance from the decimated boundary "
      "to the input boundary, as a fraction of the bounding box diagonal.");
    prm.declare_entry(
      "Boundary error weight",
      "10",
      dealii::Patterns::Double(0.0, 1e6),
      "How much the Hausdorff distance d delays the removal of a boundary "
      "vertex: priority = mean incident volume (1 + weight d / mean "
      "edge length).");
    prm.leave_subsection();
    prm.leave_subsection();
  }


  bool
  Multiresolution::enabled(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Multiresolution");
    const bool on = prm.get_bool("Enabled");
    prm.leave_subsection();
    return on;
  }


  Multiresolution::Multiresolution(dealii::ParameterHandler        &prm,
                                   const mesh::TetMesh             &input,
                                   const std::vector<unsigned int> &locked,
                                   const cut::Blade                *blade)
  {
    prm.enter_subsection("Multiresolution");
    const std::string directory = prm.get("Cache directory");
    path = parse_function("Multiresolution/Focus path", prm.get("Focus path"), 3, true);
    follows_tool = prm.get("Focus follows") == "tool";
    if (follows_tool && blade == nullptr)
      throw_error(
        "Multiresolution/Focus follows = tool: the scene has no tool to follow; set "
        "'Tool/Type' to a tool or 'Focus follows = path'.");
    distance                 = prm.get_double("Re-extraction distance");
    interval                 = prm.get_integer("Re-extraction interval");
    const std::string coarse = prm.get("Coarse stiffness");
    coarse_stiffness         = coarse == "homogenized" ? CoarseStiffness::homogenized
                               : coarse == "condensed" ? CoarseStiffness::condensed
                                                       : CoarseStiffness::rule;
    query                    = LodQueryRegistry::create_and_parse(prm.get("Query"), prm);
    BuilderParameters parameters;
    prm.enter_subsection("Builder");
    parameters.minimum_quality        = prm.get_double("Minimum quality");
    parameters.maximum_boundary_error = prm.get_double("Maximum boundary error");
    parameters.boundary_error_weight  = prm.get_double("Boundary error weight");
    prm.leave_subsection();
    prm.leave_subsection();

    for (const mesh::Point3 &x : input.get_vertices())
      box.extend(x);

    mt         = load_or_build(input, parameters, locked, directory, cache);
    lod        = std::make_unique<Lod>(mt);
    last_focus = focus(0, blade);
    query->set_focus(last_focus);
    lod->extract(*query);
    make_active_mesh();
  }


  Multiresolution::~Multiresolution() = default;


  mesh::Point3
  Multiresolution::focus(const double time, const cut::Blade *blade) const
  {
    if (follows_tool && blade != nullptr)
      return focus_of_blade(*blade);
    const dealii::Point<3> origin;
    path->set_time(time);
    return {{path->value(origin, 0), path->value(origin, 1), path->value(origin, 2)}};
  }


  mesh::Point3
  Multiresolution::focus_of_blade(const cut::Blade &blade) const
  {
    const mesh::Point3 along = mesh::sub(blade.head, blade.tail);
    // The part of the segment inside the box: the parameter interval [enter, leave]
    // that every slab between two faces of the box keeps.
    double enter = 0, leave = 1;
    for (unsigned int d = 0; d < 3 && enter <= leave; ++d)
    {
      if (along[d] == 0)
      {
        if (blade.tail[d] < box.lower[d] || blade.tail[d] > box.upper[d])
          leave = -1;
        continue;
      }
      double a = (box.lower[d] - blade.tail[d]) / along[d];
      double b = (box.upper[d] - blade.tail[d]) / along[d];
      if (a > b)
        std::swap(a, b);
      enter = std::max(enter, a);
      leave = std::min(leave, b);
    }
    if (enter <= leave)
      return mesh::lerp(blade.tail, blade.head, 0.5 * (enter + leave));
    // Outside: the point of the box nearest to the blade. The distance to the box is
    // convex along the segment, but flat where the blade runs parallel to a face: the
    // blade's nearest points then form an interval, and its middle is taken. Samples
    // bracket the interval, a golden-section search refines a single minimum.
    const auto distance_to_box = [&](const double s)
    {
      const mesh::Point3 x       = mesh::lerp(blade.tail, blade.head, s);
      double             squared = 0;
      for (unsigned int d = 0; d < 3; ++d)
      {
        const double out = std::max({box.lower[d] - x[d], 0.0, x[d] - box.upper[d]});
        squared += out * out;
      }
      return squared;
    };
    constexpr unsigned int    n = 64;
    std::array<double, n + 1> sampled;
    for (unsigned int k = 0; k <= n; ++k)
      sampled[k] = distance_to_box(double(k) / n);
    const double least = *std::min_element(sampled.begin(), sampled.end());
    const double tie   = 1e-12 * (least + mesh::dot(along, along));
    unsigned int first = 0, last = n;
    while (sampled[first] > least + tie)
      ++first;
    while (sampled[last] > least + tie)
      --last;
    double best = 0.5 * (first + last) / n;
    if (first == last)
    {
      const double ratio = 0.5 * (std::sqrt(5.0) - 1);
      double       low   = std::max(0.0, (first - 1.0) / n),
             high        = std::min(1.0, (first + 1.0) / n);
      for (unsigned int i = 0; i < 60; ++i)
      {
        const double s1 = high - ratio * (high - low), s2 = low + ratio * (high - low);
        if (distance_to_box(s1) <= distance_to_box(s2))
          high = s2;
        else
          low = s1;
      }
      if (distance_to_box(0.5 * (low + high)) < sampled[first])
        best = 0.5 * (low + high);
    }
    mesh::Point3 nearest = mesh::lerp(blade.tail, blade.head, best);
    for (unsigned int d = 0; d < 3; ++d)
      nearest[d] = std::clamp(nearest[d], box.lower[d], box.upper[d]);
    return nearest;
  }


  bool
  Multiresolution::update(const double       time,
                          const unsigned int step,
                          const cut::Blade  *blade)
  {
    const mesh::Point3 now = focus(time, blade);
    const double       moved =
      std::hypot(now[0] - last_focus[0], now[1] - last_focus[1], now[2] - last_focus[2]);
    if (moved <= distance && step - last_step < interval)
      return false;
    last_focus = now;
    last_step  = step;
    query->set_focus(now);
    return lod->extract(*query);
  }


  MtCutter::Statistics
  Multiresolution::apply_cut(const std::vector<cut::CutRecord> &records)
  {
    if (!mt_cutter)
      mt_cutter = std::make_unique<MtCutter>(mt);
    // The cut mesh stays: replayed, the records make the level of detail this mesh.
    // The MT ids of its new particles are appended in their order, after every id the
    // MT had, so the list stays increasing.
    const std::size_t          known      = vertices.size();
    const MtCutter::Statistics statistics = mt_cutter->apply(records, vertices, *lod);
    index_mesh_vertices(known);
    if (vertices.size() != mesh.n_vertices())
      throw_error("Multiresolution: internal error, the MT knows ",
                  vertices.size(),
                  " of the cut mesh's ",
                  mesh.n_vertices(),
                  " vertices.");
    return statistics;
  }


  void
  Multiresolution::set_stiffness_rule(const EdgeStiffnessRule &rule_in)
  {
    rule       = rule_in;
    built_tets = mt.fine_begin.back();
    if (coarse_stiffness == CoarseStiffness::homogenized)
      homogenized = cached_homogenized_coarse_scale(
        mt, rule, cache.file.empty() ? std::string() : cache.file + ".homogenized");
    if (coarse_stiffness == CoarseStiffness::condensed)
      condensed = condensed_edge_stiffnesses(mt, rule);
  }


  std::array<double, 6>
  Multiresolution::edge_stiffnesses(const std::uint32_t t, const mesh::Tet &cell) const
  {
    std::array<mesh::Point3, 4> x;
    for (unsigned int i = 0; i < 4; ++i)
      x[i] = mesh.vertex(cell[i]);
    if (coarse_stiffness == CoarseStiffness::homogenized)
    {
      std::array<double, 6> k = rule(x);
      if (t < built_tets && mt.destroyer[t] != mesh::invalid_index)
        for (double &v : k)
          v *= homogenized.scale;
      return k;
    }
    // Tetrahedra cuts created after the condensation take the rule.
    if (t >= condensed.size())
      return rule(x);
    // The MT stores t with its own vertex order: find the cell's edges in it.
    std::array<unsigned int, 4> position{};
    for (unsigned int i = 0; i < 4; ++i)
    {
      const auto at = std::find(mt.tets[t].begin(), mt.tets[t].end(), vertices[cell[i]]);
      if (at == mt.tets[t].end())
        throw_error("Multiresolution: internal error, a cell is not MT tetrahedron ",
                    t,
                    ".");
      position[i] = static_cast<unsigned int>(at - mt.tets[t].begin());
    }
    std::array<double, 6> k{};
    for (unsigned int e = 0; e < 6; ++e)
    {
      const auto [a, b] = mesh::TetMesh::edge_vertices[e];
      for (unsigned int f = 0; f < 6; ++f)
      {
        const auto [c, d] = mesh::TetMesh::edge_vertices[f];
        if ((c == position[a] && d == position[b])
            || (c == position[b] && d == position[a]))
          k[e] = condensed[t][f];
      }
    }
    return k;
  }


  std::vector<std::array<double, 6>>
  Multiresolution::active_cell_stiffnesses() const
  {
    // The MT tetrahedron of every active cell, by its sorted MT vertices.
    using Key = std::array<std::uint32_t, 4>;
    std::vector<std::pair<Key, std::uint32_t>> by_vertices;
    for (const std::uint32_t t : lod->active_tets())
    {
      Key key = mt.tets[t];
      std::sort(key.begin(), key.end());
      by_vertices.emplace_back(key, t);
    }
    std::sort(by_vertices.begin(), by_vertices.end());
    std::vector<std::array<double, 6>> k(mesh.n_tets());
    for (unsigned int c = 0; c < mesh.n_tets(); ++c)
    {
      Key key;
      for (unsigned int i = 0; i < 4; ++i)
        key[i] = vertices[mesh.tet(c)[i]];
      std::sort(key.begin(), key.end());
      const auto at = std::lower_bound(by_vertices.begin(),
                                       by_vertices.end(),
                                       std::make_pair(key, std::uint32_t(0)));
      if (at == by_vertices.end() || at->first != key)
        throw_error("Multiresolution: internal error, active cell ",
                    c,
                    " is no active MT tetrahedron.");
      k[c] = edge_stiffnesses(at->second, mesh.tet(c));
    }
    return k;
  }


  void
  Multiresolution::make_active_mesh()
  {
    vertices = lod->active_vertices();
    mesh     = lod->make_mesh(vertices, "level of detail");
    mesh_vertex_of.clear();
    index_mesh_vertices(0);
  }


  void
  Multiresolution::index_mesh_vertices(const std::size_t first)
  {
    mesh_vertex_of.resize(mt.n_vertices(), mesh::invalid_index);
    for (std::size_t i = first; i < vertices.size(); ++i)
      mesh_vertex_of[vertices[i]] = static_cast<std::uint32_t>(i);
  }


  unsigned int
  Multiresolution::mesh_tet_of(const std::uint32_t t) const
  {
    std::array<unsigned int, 4> corners;
    for (unsigned int k = 0; k < 4; ++k)
      corners[k] = mesh_vertex_of[mt.tets[t][k]];
    if (corners[0] != mesh::invalid_index)
      for (const unsigned int c : mesh.tets_of_vertex(corners[0]))
      {
        const mesh::Tet &q = mesh.tet(c);
        if (std::is_permutation(q.begin(), q.end(), corners.begin()))
          return c;
      }
    throw_error("Multiresolution: internal error, MT tetrahedron ",
                t,
                " of the previous level of detail is not in its mesh.");
  }


  const std::vector<unsigned int> &
  Multiresolution::apply_change(physics::TopologyUpdate &topology,
                                physics::ParticleSystem &system)
  {
    lod->last_swap(mt_removed, mt_added);
    mesh_vertex_of.resize(mt.n_vertices(), mesh::invalid_index);
    // The cells that go, while the mesh still has them, and their vertices.
    removed.clear();
    held.clear();
    for (const std::uint32_t t : mt_removed)
    {
      removed.push_back(mesh_tet_of(t));
      held.insert(held.end(),
                  mesh.tet(removed.back()).begin(),
                  mesh.tet(removed.back()).end());
    }
    // The vertices that come, with the state the previous level had where they are.
    n_new = 0;
    for (const std::uint32_t t : mt_added)
      for (const std::uint32_t g : mt.tets[t])
      {
        if (mesh_vertex_of[g] != mesh::invalid_index)
          continue;
        auto [previous, lambda] = lod->locate_in_previous(g);
        double sum              = 0;
        for (double &l : lambda)
          sum += (l = std::max(l, 0.0));
        std::array<double, 3> x{{0, 0, 0}}, v{{0, 0, 0}};
        for (unsigned int k = 0; k < 4; ++k)
        {
          const std::uint32_t corner = mesh_vertex_of[mt.tets[previous][k]];
          if (corner == mesh::invalid_index)
            throw_error("Multiresolution: internal error, the tetrahedron found for a "
                        "new vertex is not in the previous level of detail.");
          for (unsigned int d = 0; d < 3; ++d)
          {
            x[d] += lambda[k] / sum * system.position[3 * std::size_t(corner) + d];
            v[d] += lambda[k] / sum * system.velocity[3 * std::size_t(corner) + d];
          }
        }
        const mesh::Point3 &rest = mt.vertices[g];
        mesh_vertex_of[g]        = mesh.add_vertex(rest);
        system.add_particle({{rest[0], rest[1], rest[2]}}, x, v);
        vertices.push_back(g);
        ++n_new;
      }
    n_kept = vertices.size() - n_new;
    added.clear();
    for (const std::uint32_t t : mt_added)
    {
      mesh::Tet cell;
      for (unsigned int k = 0; k < 4; ++k)
        cell[k] = mesh_vertex_of[mt.tets[t][k]];
      added.push_back(cell);
    }
    // The boundary faces of a level of detail carry no id (as make_mesh() gives them).
    face_ids.assign(added.size(), {{0, 0, 0, 0}});
    topology.take_out(removed);
    added_stiffness.clear();
    if (has_coarse_stiffness())
      for (std::size_t i = 0; i < added.size(); ++i)
        added_stiffness.push_back(edge_stiffnesses(mt_added[i], added[i]));
    topology.replace(removed,
                     added,
                     face_ids,
                     has_coarse_stiffness() ? &added_stiffness : nullptr);
    // The vertices only the cells that went held.
    dead.clear();
    for (const unsigned int w : held)
      if (mesh.tets_of_vertex(w).empty())
        dead.push_back(w);
    std::sort(dead.begin(), dead.end());
    dead.erase(std::unique(dead.begin(), dead.end()), dead.end());
    for (const unsigned int w : dead)
      mesh_vertex_of[vertices[w]] = mesh::invalid_index;
    topology.remove_particles(dead);
    // The region swapped keeps its mass: a coarser or finer boundary covers a
    // slightly different volume, and the total stays ∫σ.
    topology.conserve_mass();
    topology.restore_spatial_order();
    const std::vector<unsigned int> &new_index = topology.particle_renumbering();
    renumbered_vertices.resize(mesh.n_vertices());
    for (std::size_t i = 0; i < new_index.size(); ++i)
      if (new_index[i] != mesh::invalid_index)
        renumbered_vertices[new_index[i]] = vertices[i];
    vertices.swap(renumbered_vertices);
    index_mesh_vertices(0);
    topology.notify_force_model();
    return new_index;
  }


  void
  Multiresolution::print_summary(std::ostream &out, const bool test_mode) const
  {
    const auto n_input =
      std::count(mt.destroyer.begin(), mt.destroyer.end(), mesh::invalid_index);
    out << "Multiresolution: mesh of " << n_input << " tetrahedra, " << mt.n_vertices()
        << " particles; MT of " << mt.n_nodes() << " nodes, " << mt.n_tets()
        << " tetrahedra (root " << mt.n_fine(0) << "), " << mt.memory_bytes() / 1024
        << " KiB, " << (cache.loaded ? "loaded from the cache" : "built");
    if (!test_mode)
      out << " in " << cache.seconds << " s"
          << (cache.file.empty() || cache.loaded
                ? ""
                : " (cache " + cache.reason + "; written to " + cache.file + ")");
    if (coarse_stiffness == CoarseStiffness::homogenized)
      out << "\nCoarse stiffness: the decimated cells' springs times "
          << homogenized.scale << " (energy density under unit strains: input mesh "
          << homogenized.fine_energy_density << " J/m^3, coarsest mesh "
          << homogenized.coarse_energy_density << " J/m^3 unscaled"
          << (homogenized.loaded ? "; from the cache)" : ")");
    out << "\nLevel of detail: " << mesh.n_tets() << " tetrahedra, " << mesh.n_vertices()
        << " particles, focus at (" << last_focus[0] << ", " << last_focus[1] << ", "
        << last_focus[2] << ")\n";
  }


  void
  Multiresolution::print_change(std::ostream &out,
                                const double  time,
                                const double  total_mass) const
  {
    const auto change = lod->last_change();
    out << "Level of detail at t = " << time << " s: " << mesh.n_tets() << " tetrahedra, "
        << mesh.n_vertices() << " particles (" << change[0] << " nodes applied, "
        << change[1] << " undone; " << n_new << " particles interpolated), mass "
        << total_mass << " kg\n";
  }


  void
  Multiresolution::serialize(Archive &archive)
  {
    archive.section("multiresolution");
    archive(
      mt, *query, last_focus, last_step, mesh, vertices, mesh_vertex_of, n_kept, n_new);
    lod->serialize(archive, *query);
    bool     has_mt_cutter = mt_cutter != nullptr;
    archive &has_mt_cutter;
    if (archive.loading() && has_mt_cutter && !mt_cutter)
      mt_cutter = std::make_unique<MtCutter>(mt);
    if (archive.loading() && !has_mt_cutter)
      mt_cutter.reset();
    if (mt_cutter)
      mt_cutter->serialize(archive);
  }
} // namespace lacerta::mt
