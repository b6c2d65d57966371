/**
 * @file
 * The error type Lacerta throws for bad input and failed runs.
 */
#pragma once

#include <functional>
#include <sstream>
#include <stdexcept>
#include <string>

namespace lacerta
{
  /**
   * An error the user can act on: bad input (a file, a parameter, a mesh element) or a
   * run that cannot go on (an unstable time step, a blow-up). The message names what is
   * wrong and where; `lacerta` prints it and exits with a non-zero code.
   */
  class Error : public std::runtime_error
  {
  public:
    /**
     * Creates the error with its complete message.
     */
    explicit Error(const std::string &message);
  };

  /**
   * Builds a message from any streamable pieces and throws it as an Error.
   */
  template <typename... Args>
  [[noreturn]] void
  throw_error(const Args &...pieces)
  {
    std::ostringstream message;
    message.precision(8);
    (message << ... << pieces);
    throw Error(message.str());
  }

  /**
   * Runs a program's @p body and returns its exit code; an Error, a deal.II exception
   * or any other std::exception it throws is printed as `Error: <message>` on standard
   * error and gives exit code 1. The `main` of every Lacerta program.
   */
  int
  run_reporting_errors(const std::function<int()> &body);
} // namespace lacerta
