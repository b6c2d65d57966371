// Masses (Section 3.1) and spring stiffnesses (Section 3.2).

#include <lacerta/physics/spring_fit.h>
#include <lacerta/scene/material.h>

#include <deal.II/base/function_parser.h>
#include <deal.II/base/parameter_handler.h>

#include <gtest/gtest.h>

#include "physics_test_support.h"
#include <numeric>

using namespace lacerta;

TEST(Assembly, TotalMassIsTheIntegralOfANonUniformDensityOnADistortedMesh)
{
  const mesh::TetMesh mesh =
    test_support::distorted_box(4, 0.25, dealii::Point<3>(1.0, 2.0, 0.5));
  dealii::FunctionParser<3> density(1);
  density.initialize("x,y,z", "1000*(1 + x + y*y + x*z)", {});
  const std::vector<double> masses = physics::compute_masses(mesh, density);
  const double              total  = std::accumulate(masses.begin(), masses.end(), 0.0);
  // ∫ over [0,1]x[0,2]x[0,.5] of 1 + x + y² + xz = 1 + 0.5 + 8/3 + 0.0625 per unit of
  // the x and z extents: 1*2*.5 + .5*2*.5 + (8/3)*1*.5 + (.5*.125)*2.
  const double exact = 1000 * (1.0 + 0.5 + 4.0 / 3.0 + 0.125);
  EXPECT_NEAR(total, exact, 1e-12 * exact);
  for (const double m : masses)
    EXPECT_GT(m, 0.0);
}


TEST(Assembly, EachTetrahedronGivesItsVerticesItsOwnMass)
{
  // One tetrahedron, quadratic density: Σ m_i = ∫_τ σ exactly, and m_i = ∫ σ c_i.
  const mesh::TetMesh       mesh({{0, 0, 0}, {2, 0, 0}, {0, 1, 0}, {0, 0, 3}},
                           {{0, 1, 2, 3}},
                           "tet");
  dealii::FunctionParser<3> density(1);
  density.initialize("x,y,z", "x*x", {});
  const std::vector<double> masses = physics::compute_masses(mesh, density);
  // ∫ x² over the tet = 6 V * 2! / 5! * Σ_{i<=j} x_i x_j = 6 * 1 * 2/120 * 4 = 0.4.
  EXPECT_NEAR(std::accumulate(masses.begin(), masses.end(), 0.0), 0.4, 1e-14);
  // ∫ x² c_1 (c_1 = x/2) = ∫ x³/2 = 6 V * 3!/6! * 8 / 2 = 0.2.
  EXPECT_NEAR(masses[1], 0.2, 1e-14);
}


TEST(Assembly, ConstantDensityShortcutGivesTheSameMassesToTheLastBit)
{
  // The cutter's shortcuts for a constant density and Young's modulus must not change
  // any mass or stiffness: the same quadrature sums and products, bit for bit, on
  // every cell of a distorted mesh.
  const mesh::TetMesh mesh =
    test_support::distorted_box(3, 0.25, dealii::Point<3>(1.0, 2.0, 0.5));
  const dealii::Functions::ConstantFunction<3> density(1234.5), youngs(4.7e4);
  const auto                                   sigma = physics::constant_value(density);
  ASSERT_TRUE(sigma.has_value());
  EXPECT_EQ(*sigma, 1234.5);
  const auto modulus = physics::constant_value(youngs);
  ASSERT_TRUE(modulus.has_value());
  // One object for all the cells, as the cutter keeps it.
  const physics::ConstantDensityMass for_all_cells(*sigma);
  for (unsigned int t = 0; t < mesh.n_tets(); ++t)
  {
    const auto by_function = physics::tet_mass_contributions(mesh, t, density);
    const auto by_value    = physics::tet_mass_contributions(mesh, t, *sigma);
    const auto by_volume =
      physics::constant_density_mass_contributions(mesh.volume(t), *sigma);
    const auto by_object = for_all_cells(mesh.volume(t));
    for (unsigned int i = 0; i < 4; ++i)
    {
      EXPECT_EQ(by_function[i], by_value[i]) << "tet " << t << " vertex " << i;
      EXPECT_EQ(by_function[i], by_volume[i]) << "tet " << t << " vertex " << i;
      EXPECT_EQ(by_function[i], by_object[i]) << "tet " << t << " vertex " << i;
    }
    EXPECT_EQ(physics::tet_stiffness_factor(mesh, t, youngs), *modulus * mesh.volume(t))
      << "tet " << t;
  }
  EXPECT_EQ(physics::constant_value(dealii::Functions::ZeroFunction<3>()), 0.0);
  // Functions that are not known to be constant are evaluated point by point.
  dealii::FunctionParser<3> parsed(1);
  parsed.initialize("x,y,z", "1000", {});
  EXPECT_FALSE(physics::constant_value(parsed).has_value());
  EXPECT_FALSE(
    physics::constant_value(dealii::Functions::ConstantFunction<3>(1.0, 2)).has_value());
}


TEST(Assembly, NumericDensityAndModulusAreConstantFunctionsWithTheParsersValue)
{
  // A density or Young's modulus given as a plain number gets the cut update's
  // constant shortcut, with the value the expression parser gives; an expression of
  // x, y, z does not.
  const auto material_with = [](const std::string &entry, const std::string &expression)
  {
    dealii::ParameterHandler prm;
    scene::Material::declare_parameters(prm);
    prm.enter_subsection("Material");
    prm.set(entry, expression);
    prm.leave_subsection();
    scene::Material material;
    material.parse_parameters(prm);
    return material;
  };
  for (const std::string entry : {"Density", "Youngs modulus"})
  {
    const auto field = [&](const scene::Material &material) -> const auto &
    {
      return entry == "Density" ? material.density() : material.youngs_modulus();
    };
    for (const std::string expression : {"1000", " 1.25e3 ", "0.1", "-2+7"})
    {
      const scene::Material     material = material_with(entry, expression);
      dealii::FunctionParser<3> parsed(1);
      parsed.initialize("x,y,z", expression, {});
      const auto value = physics::constant_value(field(material));
      ASSERT_TRUE(value.has_value()) << entry << " " << expression;
      EXPECT_EQ(*value, parsed.value(dealii::Point<3>())) << entry << " " << expression;
      EXPECT_EQ(field(material).value(dealii::Point<3>(0.3, -1, 2)), *value);
    }
    const scene::Material varying = material_with(entry, "1000*(1 + x)");
    EXPECT_FALSE(physics::constant_value(field(varying)).has_value()) << entry;
    EXPECT_EQ(field(varying).value(dealii::Point<3>(0.5, 0, 0)), 1500.0) << entry;
  }
}


TEST(Assembly, StiffnessOfOneTetrahedronByHand)
{
  // Unit corner tetrahedron, E = 2: V = 1/6; edges of length 1 get 2 * (1/6) / 1 = 1/3,
  // edges of length √2 get 2 * (1/6) / 2 = 1/6.
  const mesh::TetMesh      mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}},
                           {{0, 1, 2, 3}},
                           "tet");
  const physics::SpringSet springs =
    physics::compute_springs(mesh, dealii::Functions::ConstantFunction<3>(2.0));
  ASSERT_EQ(springs.size(), 6u);
  for (std::size_t s = 0; s < springs.size(); ++s)
  {
    const bool from_origin = (springs.a[s] == 0 || springs.b[s] == 0);
    EXPECT_NEAR(springs.rest_length[s], from_origin ? 1.0 : std::sqrt(2.0), 1e-15);
    EXPECT_NEAR(springs.stiffness[s], from_origin ? 1.0 / 3.0 : 1.0 / 6.0, 1e-15);
  }
}


TEST(Assembly, StiffnessSumsOverTheTetrahedraAroundAnEdge)
{
  // Two tets sharing the face (1, 2, 3); E = 1 on both.
  const mesh::TetMesh      mesh({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}},
                           {{0, 1, 2, 3}, {1, 3, 2, 4}},
                           "two tets");
  const physics::SpringSet springs =
    physics::compute_springs(mesh, dealii::Functions::ConstantFunction<3>(1.0));
  const double v0 = mesh.volume(0), v1 = mesh.volume(1);
  for (std::size_t s = 0; s < springs.size(); ++s)
  {
    const unsigned int a = springs.a[s], b = springs.b[s];
    const bool         in0 = a <= 3 && b <= 3;
    const bool         in1 = a >= 1 && b >= 1;
    const double       l2  = springs.rest_length[s] * springs.rest_length[s];
    EXPECT_NEAR(springs.stiffness[s], ((in0 ? v0 : 0) + (in1 ? v1 : 0)) / l2, 1e-14);
  }
}


TEST(Assembly, SpringFitRecoversSpringsThatRepresentTheTarget)
{
  // Five points, nine edges, known stiffnesses (one zero): their linearised stiffness
  // is the target, so the fit must give them back; a negative one cannot be a spring.
  const std::vector<mesh::Point3> x = {
    {{0, 0, 0}}, {{1, 0.1, 0}}, {{0.2, 1, 0.1}}, {{0.1, 0.3, 1.2}}, {{1, 1, 1}}};
  const std::vector<std::array<unsigned int, 2>> edges = {{{0, 1}},
                                                          {{0, 2}},
                                                          {{0, 3}},
                                                          {{1, 2}},
                                                          {{1, 3}},
                                                          {{2, 3}},
                                                          {{1, 4}},
                                                          {{2, 4}},
                                                          {{3, 4}}};
  for (const bool with_negative : {false, true})
  {
    std::vector<double> k = {3, 1, 0, 2.5, 0.7, 4, 1.5, 2, 0.3};
    if (with_negative)
      k[4] = -0.5;
    std::vector<double> target(9 * x.size() * x.size(), 0.0);
    const std::size_t   n3 = 3 * x.size();
    for (std::size_t e = 0; e < edges.size(); ++e)
    {
      const auto [a, b]    = edges[e];
      const mesh::Point3 d = mesh::sub(x[b], x[a]);
      for (unsigned int r = 0; r < 3; ++r)
        for (unsigned int c = 0; c < 3; ++c)
        {
          const double v = k[e] * d[r] * d[c] / mesh::dot(d, d);
          target[(3 * a + r) * n3 + 3 * a + c] += v;
          target[(3 * b + r) * n3 + 3 * b + c] += v;
          target[(3 * a + r) * n3 + 3 * b + c] -= v;
          target[(3 * b + r) * n3 + 3 * a + c] -= v;
        }
    }
    const std::vector<double> fit = physics::fit_spring_stiffnesses(x, edges, target);
    ASSERT_EQ(fit.size(), edges.size());
    for (std::size_t e = 0; e < edges.size(); ++e)
    {
      EXPECT_GE(fit[e], 0.0);
      if (!with_negative)
        EXPECT_NEAR(fit[e], k[e], 1e-12) << "edge " << e;
    }
    if (with_negative)
      EXPECT_EQ(fit[4], 0.0);
  }
}
