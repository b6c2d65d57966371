#include <lacerta/base/archive.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/force_model.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/physics/stability_bound.h>

#include <algorithm>
#include <cmath>

namespace lacerta::physics
{
  namespace
  {
    /**
     * Whether row @p a with bound @p lambda_a beats row @p b with @p lambda_b: higher,
     * or equal and first. A bound that is not a number wins (the caller reports it).
     */
    bool
    higher_row(const double       lambda_a,
               const unsigned int a,
               const double       lambda_b,
               const unsigned int b)
    {
      if (std::isnan(lambda_a) || std::isnan(lambda_b))
        return std::isnan(lambda_a) && (!std::isnan(lambda_b) || a < b);
      return lambda_a > lambda_b || (lambda_a == lambda_b && a < b);
    }
  } // namespace


  void
  StabilityBound::compute(const ParticleSystem &system)
  {
    const GershgorinTerms terms = gershgorin_terms(system, system.position.data());
    first_weights               = gershgorin_row_weights(system, terms);
    weights                     = refined_row_weights(system, terms, first_weights);
    lambda                      = weighted_frequency_bounds(system, terms, weights);
    stiffest                    = terms.stiffest_spring;
    build_tree(system.n_particles());
    check.clear();
  }


  std::optional<FrequencyBound>
  StabilityBound::bound_with_kept_weights(const ParticleSystem &system) const
  {
    if (leaves == 0 || weights.size() != system.n_particles())
      return std::nullopt;
    std::vector<unsigned int> stiffest_spring;
    const std::vector<double> rows = weighted_frequency_bounds_at(system,
                                                                  system.position.data(),
                                                                  weights,
                                                                  stiffest_spring);
    // The highest row, as bound() picks it from the kept rows.
    unsigned int best = 0;
    for (unsigned int i = 1; i < rows.size(); ++i)
      if (higher_row(rows[i], i, rows[best], best))
        best = i;
    FrequencyBound result;
    if (rows.empty() || (!(rows[best] > 0) && !std::isnan(rows[best])))
      return result;
    result.particle = best;
    result.spring   = stiffest_spring[best];
    result.omega    = std::sqrt(rows[best]);
    return result;
  }


  bool
  StabilityBound::kept_weights_within(const ParticleSystem &system,
                                      const double          squared_omega)
  {
    const unsigned int n = system.n_particles();
    if (leaves == 0 || weights.size() != n)
      return false;
    const bool springs_only =
      !(system.has_force_model() && system.force_model().has_element_stiffness());
    if (!springs_only)
      return rows_within(system, squared_omega);
    if (check.isotropic.size() != n)
      check.isotropic = isotropic_frequency_bounds(system, weights);
    if (check.rows.size() != n || check.allowed.size() != system.springs.size())
      return rows_within(system, squared_omega);
    if (check.limit != squared_omega)
    {
      check.allowed = spring_motion_allowances(
        system, check.position.data(), check.rows, check.isotropic, squared_omega);
      check.limit = squared_omega;
    }
    // The rows the reference does not settle: those at a spring that collapsed or
    // moved past its allowance.
    row_mark.resize(n, 0);
    ++mark;
    rows.clear();
    ends.clear();
    append_ends_of_springs_to_bound_again(
      system, system.position.data(), check.position.data(), check.allowed, ends);
    for (const unsigned int p : ends)
      add_row(p);
    if (rows.empty())
      return true;
    // Those are bounded from the springs around them (the mesh's stars, whose edges
    // must be the springs), unless they are many: then every row is, and the current
    // positions become the reference.
    if (!has_local_rows(system) || rows.size() > n / 4)
      return rows_within(system, squared_omega);
    bound_rows(system, 0);
    return std::all_of(row_lambda.begin(),
                       row_lambda.end(),
                       [&](const double l) { return l <= squared_omega; });
  }


  bool
  StabilityBound::rows_within(const ParticleSystem &system, const double squared_omega)
  {
    std::vector<unsigned int> spring;
    std::vector<double>       all =
      weighted_frequency_bounds_at(system, system.position.data(), weights, spring);
    const bool within = std::all_of(all.begin(),
                                    all.end(),
                                    [&](const double l) { return l <= squared_omega; });
    // For a force model of springs only, these positions and rows are the reference
    // of the next checks (unneeded if the bound is computed anew, which clears them).
    check.rows.clear();
    check.allowed.clear();
    if (within && check.isotropic.size() == system.n_particles())
    {
      check.position = system.position;
      check.rows     = std::move(all);
      check.allowed  = spring_motion_allowances(
        system, check.position.data(), check.rows, check.isotropic, squared_omega);
      check.limit = squared_omega;
    }
    return within;
  }


  void
  StabilityBound::CheckReference::clear()
  {
    isotropic.clear();
    rows.clear();
    allowed.clear();
  }


  void
  StabilityBound::update(const ParticleSystem            &system,
                         const std::vector<unsigned int> &changed)
  {
    check.clear();
    // The local rows walk the mesh's stars, whose edges are the springs.
    if (!has_local_rows(system) || leaves == 0 || system.all_particles_changed())
    {
      compute(system);
      return;
    }
    const unsigned int n      = system.n_particles();
    const unsigned int before = static_cast<unsigned int>(lambda.size());
    // Particles removed from the end (a coarser level of detail) leave the tournament
    // first, while their bounds can still be read.
    for (unsigned int i = n; i < before; ++i)
    {
      tree[leaves + i] = none;
      for (unsigned int k = (leaves + i) / 2; k >= 1; k /= 2)
        tree[k] = beats(tree[2 * k + 1], tree[2 * k]) ? tree[2 * k + 1] : tree[2 * k];
    }
    lambda.resize(n, 0.0);
    stiffest.resize(n, 0);
    first_weights.resize(n, 1.0);
    weights.resize(n, 1.0);
    if (n > leaves)
      build_tree(n);
    row_mark.resize(n, 0);
    // The changed and appended particles get new weights (their rows with all weights
    // 1, then their rows with those); any positive weights give a bound, so the others
    // keep theirs until the next compute(). A row depends on its springs and tetrahedra
    // and on its neighbours' masses and weights: the changed particles and every vertex
    // of their stars are bounded again.
    ++mark;
    rows.clear();
    for (const unsigned int p : changed)
      add_row(p);
    for (unsigned int p = before; p < n; ++p)
      add_row(p);
    const std::size_t n_reweighted = rows.size();
    for (std::size_t r = 0; r < n_reweighted; ++r)
      add_star(system, rows[r]);
    bound_rows(system, n_reweighted);
    for (std::size_t r = 0; r < rows.size(); ++r)
      set(rows[r], row_lambda[r], row_spring[r]);
  }


  bool
  StabilityBound::has_local_rows(const ParticleSystem &system)
  {
    return system.mesh != nullptr && system.mesh->has_local_updates()
           && system.mesh->n_edges() == system.springs.size();
  }


  void
  StabilityBound::bound_rows(const ParticleSystem &system, const std::size_t n_reweighted)
  {
    row_lambda.resize(rows.size());
    row_spring.resize(rows.size());
    gershgorin_rows(system,
                    system.position.data(),
                    rows,
                    n_reweighted,
                    first_weights,
                    weights,
                    scratch,
                    row_lambda.data(),
                    row_spring.data());
  }


  void
  StabilityBound::add_row(const unsigned int p)
  {
    if (row_mark[p] != mark)
    {
      row_mark[p] = mark;
      rows.push_back(p);
    }
  }


  void
  StabilityBound::add_star(const ParticleSystem &system, const unsigned int p)
  {
    add_row(p);
    for (const unsigned int t : system.mesh->tets_of_vertex(p))
      for (const unsigned int v : system.mesh->tet(t))
        add_row(v);
  }


  FrequencyBound
  StabilityBound::bound() const
  {
    FrequencyBound result;
    if (leaves == 0 || tree[1] == none)
      return result;
    const double highest = lambda[tree[1]];
    if (!(highest > 0) && !std::isnan(highest))
      return result;
    result.particle = tree[1];
    result.spring   = stiffest[tree[1]];
    result.omega    = std::sqrt(highest);
    return result;
  }


  void
  StabilityBound::build_tree(const unsigned int n)
  {
    leaves = 1;
    while (leaves < n)
      leaves *= 2;
    tree.assign(2 * std::size_t(leaves), none);
    for (unsigned int i = 0; i < n; ++i)
      tree[leaves + i] = i;
    for (unsigned int k = leaves - 1; k >= 1; --k)
      tree[k] = beats(tree[2 * k + 1], tree[2 * k]) ? tree[2 * k + 1] : tree[2 * k];
  }


  void
  StabilityBound::set(const unsigned int i,
                      const double       squared_omega,
                      const unsigned int spring)
  {
    lambda[i]        = squared_omega;
    stiffest[i]      = spring;
    tree[leaves + i] = i;
    for (unsigned int k = (leaves + i) / 2; k >= 1; k /= 2)
      tree[k] = beats(tree[2 * k + 1], tree[2 * k]) ? tree[2 * k + 1] : tree[2 * k];
  }


  bool
  StabilityBound::beats(const unsigned int a, const unsigned int b) const
  {
    if (a == none)
      return false;
    if (b == none)
      return true;
    // A bound that is not a number wins: the caller reports it.
    return higher_row(lambda[a], a, lambda[b], b);
  }


  void
  StabilityBound::serialize(Archive &archive)
  {
    archive.section("stability bound");
    archive(lambda, stiffest, first_weights, weights, tree, leaves);
    // The periodic check's reference is worked out again at the next check.
    check.clear();
  }
} // namespace lacerta::physics
