#include <lacerta/mt/lod_query.h>

#include <atomic>
#include <cmath>

namespace lacerta::mt
{
  void
  LodQuery::set_focus(const mesh::Point3 &)
  {
  }


  double
  LodQuery::focus_travel() const
  {
    return 0;
  }


  double
  LodQuery::focus_slack(const mesh::Point3 &, double, double) const
  {
    return 0;
  }


  std::uint64_t
  LodQuery::next_identity()
  {
    static std::atomic<std::uint64_t> counter{0};
    return ++counter;
  }


  double
  LodQuery::error_of_cell_size(const double h)
  {
    return h * h * h / (6 * std::sqrt(2.0));
  }
} // namespace lacerta::mt
