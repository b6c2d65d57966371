/**
 * @file
 * The error-against-run-time study (`set Mode = study`): runs every variant of a scene
 * (mesh refinement x model x integrator x time step), times it, measures its error
 * against a FEM P2 reference and writes study.csv and study.png.
 */
#pragma once

#include <lacerta/fem/elasticity.h>

#include <deal.II/base/parameter_handler.h>

#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

namespace lacerta::scene
{
  class Scene;
}

namespace lacerta::fem
{
  /**
   * The scene of a study variant: the scene of @p prm with `Mesh/Box/Repetitions`
   * multiplied by @p factor, and the springs and force model of the study model
   * @p model ('springs', 'fitted springs', 'volume springs', 'corotated fem'; any other
   * name gets the paper's springs). @p prm is left as it was. The scene must use the
   * box source, else an Error.
   */
  std::unique_ptr<scene::Scene>
  make_study_scene(dealii::ParameterHandler &prm,
                   unsigned int              factor,
                   const std::string        &model);

  /// The solver of the study's reference: FEM P2, CG to a relative 1e-11.
  SolverParameters
  study_reference_parameters();


  /**
   * One row of the study: a variant, its cost and its error.
   */
  struct StudyRow
  {
    std::string  variant, model, integrator;
    unsigned int tets      = 0;
    double       time_step = 0;
    double       wall_time = 0;
    double       error_l2  = 0;
    double       error_max = 0;
    /// The Poisson ratio of the variant and of its reference.
    double poisson_ratio = 0;
  };


  /**
   * The study driver. Variants share the scene of the parameter file; a refinement
   * multiplies `Mesh/Box/Repetitions`. Static analysis: springs by direct solve,
   * dynamic relaxation or an explicit integrator run to `End time`, FEM by CG-AMG;
   * the reference is FEM P2 on the mesh refined `Reference refinement` times.
   * Dynamic analysis: springs by explicit integrators, FEM by Newmark, errors over the
   * nodes at `Number of samples` times, against FEM P2 Newmark on the reference mesh.
   * FEM runs on all MPI ranks; the serial spring variants run on every rank.
   * With `Poisson ratios`, every variant and the reference run at each of them in turn.
   */
  class Study
  {
  public:
    /// Declares `subsection Study`.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Reads the study from @p prm (the whole scene's parameters).
    explicit Study(dealii::ParameterHandler &prm);

    /// Runs every variant, prints the table and writes study.csv (and study.png).
    std::vector<StudyRow>
    run();

  private:
    /// Every variant at the Poisson ratio @p nu, against the reference at @p nu.
    std::vector<StudyRow>
    run_at_poisson_ratio(double nu, std::ostream &out);

    /// The reference FEM P2 solution at the sample times, with its scene.
    struct Reference;

    /// The rows of one model at one refinement, against @p reference.
    std::vector<StudyRow>
    run_model(const std::string &model,
              unsigned int       refinement,
              double             nu,
              const Reference   &reference,
              std::ostream      &out);

    /// Writes study.csv and, if asked, study.png (root rank only).
    void
    write_results(const std::vector<StudyRow> &rows, std::ostream &out) const;

    dealii::ParameterHandler &prm;
    bool                      dynamic;
    std::vector<unsigned int> refinements;
    std::vector<std::string>  models, integrators;
    std::vector<double>       time_steps;
    /// The Poisson ratios of the sweep; empty: the scene's `Material/Poisson ratio`.
    std::vector<double> poisson_ratios;
    /// The sample times: 'End time' (static) or 'Number of samples' up to it.
    std::vector<double> sample_times;
    unsigned int        reference_refinement;
    double              reference_time_step;
    unsigned int        n_samples;
    /// How many lowest frequencies to print per model and refinement (0: none).
    unsigned int n_frequencies = 0;
    bool         plot;
    std::string  plot_script, output_directory;
    bool         test_mode;
  };
} // namespace lacerta::fem
