#include <lacerta/base/input_path.h>

#include <filesystem>

namespace lacerta
{
  namespace
  {
    std::string &
    input_directory()
    {
      static std::string directory;
      return directory;
    }
  } // namespace


  void
  set_input_directory(const std::string &directory)
  {
    input_directory() = directory;
  }


  std::string
  resolve_input_path(const std::string &file_name)
  {
    const std::filesystem::path path(file_name);
    if (path.is_absolute() || input_directory().empty())
      return file_name;
    const std::filesystem::path beside_input =
      std::filesystem::path(input_directory()) / path;
    return std::filesystem::exists(beside_input) ? beside_input.string() : file_name;
  }


  bool
  ends_with(const std::string &file_name, const std::string &suffix)
  {
    return file_name.size() >= suffix.size()
           && file_name.compare(file_name.size() - suffix.size(), suffix.size(), suffix)
                == 0;
  }
} // namespace lacerta
