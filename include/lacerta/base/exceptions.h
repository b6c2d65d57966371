/**
 * @file
 * The error type Lacerta throws for bad input and failed runs.
 */
#pragma once

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
} // namespace lacerta
