/**
 * @file
 * Where relative file names in a parameter file are looked up.
 */
#pragma once

#include <string>

namespace lacerta
{
  /**
   * Sets the directory of the parameter file being read; relative file names in it are
   * looked up there first (so a scene works from any working directory).
   */
  void
  set_input_directory(const std::string &directory);

  /**
   * Resolves @p file_name: an absolute name is returned as it is; a relative one is
   * taken from the input directory if the file exists there, else from the working
   * directory.
   */
  std::string
  resolve_input_path(const std::string &file_name);

  /**
   * Whether @p file_name ends with @p suffix (an extension such as ".msh").
   */
  bool
  ends_with(const std::string &file_name, const std::string &suffix);
} // namespace lacerta
