// lacerta-bench: benchmark programs that print figures (never timed tests).

#include "benchmark_registry.h"
#include <cstdio>
#include <exception>
#include <iostream>

namespace lacerta::bench
{
  std::map<std::string, Benchmark> &
  registry()
  {
    static std::map<std::string, Benchmark> benchmarks;
    return benchmarks;
  }


  BenchmarkRegistrar::BenchmarkRegistrar(
    const std::string                                   &name,
    const std::string                                   &description,
    std::function<int(const std::vector<std::string> &)> run)
  {
    registry()[name] = Benchmark{description, std::move(run)};
  }


  void
  print_figure(const std::string &name, const double value, const std::string &unit)
  {
    std::printf("%s: %.6g %s\n", name.c_str(), value, unit.c_str());
    std::fflush(stdout);
  }
} // namespace lacerta::bench


int
main(int argc, char **argv)
{
  using namespace lacerta::bench;
  const std::string command = argc > 1 ? argv[1] : "--help";
  const auto        found   = registry().find(command);
  if (found == registry().end())
  {
    const bool asked = (command == "--help" || command == "-h");
    (asked ? std::cout : std::cerr)
      << (asked ? "" : "Unknown benchmark '" + command + "'.\n")
      << "Usage: lacerta-bench <benchmark> [options]\nBenchmarks:\n";
    for (const auto &[name, benchmark] : registry())
      (asked ? std::cout : std::cerr)
        << "  " << name << ": " << benchmark.description << "\n";
    return asked ? 0 : 1;
  }
  try
  {
    return found->second.run(std::vector<std::string>(argv + 2, argv + argc));
  }
  catch (const std::exception &error)
  {
    // Bad input (a parameter file that cannot be read, a bad entry): the message,
    // and a non-zero exit, not an abort.
    std::cerr << "lacerta-bench " << command << ": " << error.what() << "\n";
    return 1;
  }
}
