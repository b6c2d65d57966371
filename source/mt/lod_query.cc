#include <lacerta/mt/lod_query.h>

#include <cmath>

namespace lacerta::mt
{
  void
  LodQuery::set_focus(const mesh::Point3 &)
  {
  }


  double
  LodQuery::error_of_cell_size(const double h)
  {
    return h * h * h / (6 * std::sqrt(2.0));
  }
} // namespace lacerta::mt
