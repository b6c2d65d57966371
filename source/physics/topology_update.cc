#include <lacerta/mesh/point.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/topology_update.h>

#include <algorithm>
#include <numeric>

namespace lacerta::physics
{
  TopologyUpdate::TopologyUpdate(mesh::TetMesh                     &mesh_in,
                                 ParticleSystem                    &system_in,
                                 const dealii::Function<3, double> &density_in,
                                 const dealii::Function<3, double> &youngs_modulus_in,
                                 const double                       mass_scale_in)
      : mesh(mesh_in)
      , system(system_in)
      , density(density_in)
      , youngs_modulus(youngs_modulus_in)
      , mass_scale(mass_scale_in)
  {
    mesh.enable_local_updates();
    if (const auto sigma = constant_value(density))
      constant_density_mass.emplace(*sigma);
    constant_youngs_modulus = constant_value(youngs_modulus);
    const auto &k           = system.springs.stiffness;
    if ((system.fitted_springs || !system.cell_stiffness.empty()) && !k.empty())
      stiffness_floor = 1e-6 * *std::max_element(k.begin(), k.end());
  }


  TopologyUpdate::CellTerms
  TopologyUpdate::cell_terms(const unsigned int t) const
  {
    // A constant density and Young's modulus (the common case) need no Function call
    // and one volume per cell instead of two; the masses and stiffness factors are the
    // same to the last bit.
    CellTerms terms;
    if (constant_density_mass && constant_youngs_modulus)
    {
      const double volume = mesh.volume(t);
      terms = {(*constant_density_mass)(volume), *constant_youngs_modulus * volume};
    }
    else
      terms = {constant_density_mass ? (*constant_density_mass)(mesh.volume(t))
                                     : tet_mass_contributions(mesh, t, density),
               tet_stiffness_factor(mesh, t, youngs_modulus)};
    if (mass_scale != 1.0)
      for (double &m : terms.mass)
        m *= mass_scale;
    return terms;
  }


  std::array<double, 6>
  TopologyUpdate::rule_stiffnesses(const unsigned int t, const CellTerms &terms) const
  {
    if (system.fitted_springs)
      return fitted_edge_stiffnesses(mesh, t, youngs_modulus, system.poisson_ratio);
    std::array<double, 6> squared_length;
    for (unsigned int i = 0; i < 6; ++i)
    {
      const double length = system.springs.rest_length[mesh.tet_edges(t)[i]];
      squared_length[i]   = length * length;
    }
    return paper_edge_stiffnesses(terms.stiffness_factor, squared_length);
  }


  void
  TopologyUpdate::add_cell_terms(const unsigned int           t,
                                 const double                 sign,
                                 const std::array<double, 6> *given)
  {
    SpringSet       &springs = system.springs;
    const CellTerms  terms   = cell_terms(t);
    const mesh::Tet &tet     = mesh.tet(t);
    for (unsigned int i = 0; i < 4; ++i)
    {
      system.mass[tet[i]] += sign * terms.mass[i];
      touched.push_back(tet[i]);
      delta += sign * terms.mass[i];
      (sign > 0 ? put_in : taken_out) += terms.mass[i];
    }
    volume_change += sign * mesh.volume(t);
    std::array<double, 6> k;
    if (!system.cell_stiffness.empty())
    {
      if (sign > 0)
        system.cell_stiffness[t] = given ? *given : rule_stiffnesses(t, terms);
      k = system.cell_stiffness[t];
    }
    else
      k = rule_stiffnesses(t, terms);
    for (unsigned int i = 0; i < 6; ++i)
    {
      const unsigned int e = mesh.tet_edges(t)[i];
      springs.stiffness[e] += sign * k[i];
      changed_springs.push_back(e);
    }
  }


  void
  TopologyUpdate::take_out(const std::vector<unsigned int> &removed)
  {
    taken_out    = 0;
    removed_mass = 0;
    new_index.clear();
    for (const unsigned int t : removed)
      add_cell_terms(t, -1, nullptr);
  }


  const std::vector<unsigned int> &
  TopologyUpdate::replace(const std::vector<unsigned int>                &removed,
                          const std::vector<mesh::Tet>                   &added,
                          const std::vector<std::array<unsigned int, 4>> &face_ids,
                          const std::vector<std::array<double, 6>>       *added_stiffness)
  {
    mesh.replace_tets(removed, added, face_ids, added_ids, update_of_mesh);
    // The cells' kept stiffnesses follow the cells moved into freed slots.
    auto &cell_stiffness = system.cell_stiffness;
    if (!cell_stiffness.empty())
    {
      for (const auto &[to, from] : update_of_mesh.tet_moves)
        cell_stiffness[to] = cell_stiffness[from];
      cell_stiffness.resize(mesh.n_tets());
    }
    // Springs follow the edges: appended, moved into retired slots, restiffened.
    SpringSet  &springs = system.springs;
    const auto &edges   = mesh.get_edges();
    for (unsigned int i = 0; i < update_of_mesh.n_added_edges; ++i)
    {
      const unsigned int e = static_cast<unsigned int>(springs.size());
      changed_springs.push_back(e);
      springs.push_back(edges[e][0],
                        edges[e][1],
                        0.0,
                        mesh::distance(mesh.vertex(edges[e][1]),
                                       mesh.vertex(edges[e][0])));
    }
    // The mesh copied its last edge into each retired slot: so do the springs.
    for (const auto &move : update_of_mesh.edge_moves)
    {
      changed_springs.push_back(move[0]);
      springs.retire(move[0]);
    }
    // A cell moved into a freed slot keeps its particles and springs, but the force
    // model's data by cell must follow it: its edges count as changed.
    for (const auto &move : update_of_mesh.tet_moves)
      for (const unsigned int e : mesh.tet_edges(move[0]))
        changed_springs.push_back(e);
    put_in = 0;
    for (std::size_t i = 0; i < added_ids.size(); ++i)
      add_cell_terms(added_ids[i],
                     +1,
                     added_stiffness ? &(*added_stiffness)[i] : nullptr);
    // Fitted and kept stiffnesses keep the token stiffness where every cell of an edge
    // dropped it (and where rounding left a sum a hair below it).
    if (system.fitted_springs || !cell_stiffness.empty())
      for (const unsigned int e : changed_springs)
        if (e < springs.size())
          springs.stiffness[e] = std::max(springs.stiffness[e], stiffness_floor);
    return added_ids;
  }


  void
  TopologyUpdate::conserve_mass()
  {
    if (!(put_in > 0))
      return;
    const double extra = (taken_out + removed_mass) / put_in - 1;
    for (const unsigned int t : added_ids)
    {
      const CellTerms  terms = cell_terms(t);
      const mesh::Tet &tet   = mesh.tet(t);
      for (unsigned int i = 0; i < 4; ++i)
      {
        system.mass[tet[i]] += extra * terms.mass[i];
        delta += extra * terms.mass[i];
      }
    }
    put_in       = taken_out + removed_mass;
    removed_mass = 0;
  }


  const std::vector<unsigned int> &
  TopologyUpdate::remove_particles(const std::vector<unsigned int> &dead)
  {
    const unsigned int n_before = system.n_particles();
    // What the particles still hold (rounding, earlier corrections of
    // conserve_mass()) leaves with them; a redistributed share (mass_shift) is the
    // mass balancer's to settle.
    for (const unsigned int v : dead)
      removed_mass += system.mass[v] - system.mass_shift[v];
    vertex_moves.clear();
    mesh.remove_vertices(dead, vertex_moves);
    system.remove_particles(vertex_moves, static_cast<unsigned int>(dead.size()));
    // The springs of a moved particle take its new id as their end, in the order of
    // the mesh's edge (lower id first).
    SpringSet  &springs = system.springs;
    const auto &edges   = mesh.get_edges();
    for (const auto &move : vertex_moves)
    {
      const unsigned int v = move[0];
      if (v >= mesh.n_vertices())
        continue;
      for (const unsigned int t : mesh.tets_of_vertex(v))
        for (const unsigned int e : mesh.tet_edges(t))
          if (edges[e][0] == v || edges[e][1] == v)
          {
            springs.a[e] = edges[e][0];
            springs.b[e] = edges[e][1];
            changed_springs.push_back(e);
          }
    }
    // Where every particle went: follow the moves slot by slot.
    std::vector<unsigned int> occupant(n_before);
    std::iota(occupant.begin(), occupant.end(), 0u);
    for (const auto &[to, from] : vertex_moves)
      occupant[to] = occupant[from];
    new_index.assign(n_before, mesh::invalid_index);
    for (unsigned int slot = 0; slot < system.n_particles(); ++slot)
      new_index[occupant[slot]] = slot;
    return new_index;
  }


  bool
  TopologyUpdate::restore_spatial_order()
  {
    const std::vector<unsigned int> order = mesh.spatial_vertex_order();
    if (!(mesh.index_spread() > 1.25 * mesh.index_spread(order)))
      return false;
    mesh.renumber_vertices(order);
    system.renumber_particles(order);
    SpringSet  &springs = system.springs;
    const auto &edges   = mesh.get_edges();
    for (std::size_t e = 0; e < springs.size(); ++e)
    {
      springs.a[e] = edges[e][0];
      springs.b[e] = edges[e][1];
    }
    if (new_index.empty())
    {
      new_index.resize(order.size());
      std::iota(new_index.begin(), new_index.end(), 0u);
    }
    for (unsigned int &i : new_index)
      if (i != mesh::invalid_index)
        i = order[i];
    touched.clear();
    changed_springs.clear();
    renumbered = true;
    return true;
  }


  void
  TopologyUpdate::notify_force_model()
  {
    if (renumbered)
    {
      system.refresh_force_model();
      renumbered = false;
      return;
    }
    if (changed_springs.empty())
      return;
    system.springs_changed(changed_springs);
    changed_springs.clear();
  }
} // namespace lacerta::physics
