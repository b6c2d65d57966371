// Expressions from the parameter file: whether they name the position, and the moving
// handle's shortcut for those that do not.
#include <lacerta/base/exceptions.h>
#include <lacerta/base/parsed_function.h>

#include <gtest/gtest.h>

#include <string>

namespace lacerta
{
  TEST(ParsedFunction, UsesPositionFindsTheVariablesOnly)
  {
    for (const std::string expression :
         {"x", "0.01*y; 0; 0", "0; 0; sin(z)", "t*x+1", "(x)", "-0.01*min(t/0.5, 1)+z"})
      EXPECT_TRUE(uses_position(expression)) << expression;
    // Function names, numbers with exponents and time are not the position.
    for (const std::string expression : {"-0.01*min(t/0.5, 1); 0; 0",
                                         "exp(-t)",
                                         "1e-3*t; 2.5E+2; 0",
                                         "0; 0; 0",
                                         "max(t, 1e-2)*_pi",
                                         ""})
      EXPECT_FALSE(uses_position(expression)) << expression;
  }


  TEST(ParsedFunction, ATranslationIsTheSameAtEveryPoint)
  {
    // What the moving handle relies on: an expression that names no coordinate has one
    // value everywhere, bit for bit.
    const std::string expression = "-0.01*min(t/0.5, 1); 0.003*sin(40*t); 1e-3*t*t";
    ASSERT_FALSE(uses_position(expression));
    const auto f = parse_function("Test/Displacement", expression, 3, true);
    f->set_time(0.37);
    for (const dealii::Point<3> &p :
         {dealii::Point<3>(0.1, -2, 3), dealii::Point<3>(1e3, 0, -1e-7)})
      for (unsigned int d = 0; d < 3; ++d)
        EXPECT_EQ(f->value(p, d), f->value(dealii::Point<3>(), d));
  }
} // namespace lacerta
