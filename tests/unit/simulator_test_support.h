// Helpers shared by the unit tests that run whole scenes with the Simulator.
#pragma once

#include <lacerta/simulator/simulator.h>

#include <deal.II/base/parameter_handler.h>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

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
} // namespace lacerta::test
