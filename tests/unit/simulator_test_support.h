// Helpers shared by the unit tests that run whole scenes with the Simulator.
#pragma once

#include <lacerta/simulator/simulator.h>

#include <deal.II/base/parameter_handler.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace lacerta::test
{
  /**
   * Runs the scene given by the parameter text @p parameters, written to @p file for
   * the run (and removed once read), with what it prints to std::cout swallowed.
   */
  inline void
  run_scene_quietly(const std::string &file, const std::string &parameters)
  {
    {
      std::ofstream out(file);
      out << parameters;
    }
    dealii::ParameterHandler prm;
    Simulator::read_parameters(file, prm);
    std::filesystem::remove(file);
    std::ostringstream quiet;
    auto *const        old = std::cout.rdbuf(quiet.rdbuf());
    try
    {
      Simulator(prm, file).run();
    }
    catch (...)
    {
      std::cout.rdbuf(old);
      throw;
    }
    std::cout.rdbuf(old);
  }

  /// A row of the `fem comparison` postprocessor's comparison.csv: time, relative L2
  /// and largest error, then the probes' columns in their order.
  struct ComparisonRow
  {
    double              time = 0, error_rel_l2 = 0, error_max = 0;
    std::vector<double> probe;
  };

  /// The rows of comparison.csv in @p directory (none when the file is missing).
  inline std::vector<ComparisonRow>
  read_comparison_rows(const std::filesystem::path &directory)
  {
    std::ifstream              in(directory / "comparison.csv");
    std::string                line;
    std::vector<ComparisonRow> rows;
    std::getline(in, line);
    while (std::getline(in, line))
    {
      std::istringstream row(line);
      ComparisonRow      r;
      char               comma;
      row >> r.time >> comma >> r.error_rel_l2 >> comma >> r.error_max;
      double value = 0;
      while (row >> comma >> value)
        r.probe.push_back(value);
      rows.push_back(r);
    }
    return rows;
  }
} // namespace lacerta::test
