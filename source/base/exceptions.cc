#include <lacerta/base/exceptions.h>

namespace lacerta
{
  Error::Error(const std::string &message)
      : std::runtime_error(message)
  {
  }
} // namespace lacerta
