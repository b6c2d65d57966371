/**
 * @file
 * The sub-commands of `lacerta-bench`: every benchmark registers itself by name and
 * prints its figures as lines `name: value unit`.
 */
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace lacerta::bench
{
  /**
   * One benchmark: a description for `lacerta-bench --help` and the function that runs
   * it with the remaining command-line arguments. The function returns the exit code.
   */
  struct Benchmark
  {
    std::string                                          description;
    std::function<int(const std::vector<std::string> &)> run;
  };

  /**
   * The benchmarks known to `lacerta-bench`, by sub-command name.
   */
  std::map<std::string, Benchmark> &
  registry();

  /**
   * Registers a benchmark at program start; used through LACERTA_REGISTER_BENCHMARK.
   */
  struct BenchmarkRegistrar
  {
    BenchmarkRegistrar(const std::string                                   &name,
                       const std::string                                   &description,
                       std::function<int(const std::vector<std::string> &)> run);
  };

  /**
   * Prints one figure in the format every benchmark uses: `name: value unit`.
   */
  void
  print_figure(const std::string &name, double value, const std::string &unit);
} // namespace lacerta::bench

#define LACERTA_REGISTER_BENCHMARK(name, description, function)                       \
  static const lacerta::bench::BenchmarkRegistrar lacerta_bench_registrar_##function( \
    name, description, function)
