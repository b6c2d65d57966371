/**
 * @file
 * Queries that say how fine a level of detail must be where (plugins, Section 4).
 */
#pragma once

#include <lacerta/base/plugins.h>
#include <lacerta/mesh/tet_mesh.h>

#include <cstdint>
#include <string>

namespace lacerta
{
  class Archive;
}
namespace lacerta::mt
{
  /**
   * A query ε(x): the largest approximation error (average tetrahedron volume, m³,
   * Section 4.1) the level of detail may have at x. Plugins express it as a cell size
   * h (the edge of a regular tetrahedron of that volume, ε = h³ / (6√2)), which is
   * what a user thinks in.
   */
  class LodQuery
  {
  public:
    /// Kind name used in messages and in the documentation.
    static std::string
    plugin_kind()
    {
      return "level of detail query";
    }

    virtual ~LodQuery() = default;

    /// Reads the plugin's parameters from its subsection.
    virtual void
    parse_parameters(dealii::ParameterHandler &prm) = 0;

    /// Moves the focus of the query (the tool's position); ignored by uniform queries.
    virtual void
    set_focus(const mesh::Point3 &focus);

    /**
     * Length of the path the focus has travelled through set_focus() since the query
     * was made; 0 for queries that ignore the focus. With focus_slack() it tells an
     * incremental extraction which nodes cannot have changed.
     */
    virtual double
    focus_travel() const;

    /// Writes or reads the query's state (the focus) for a checkpoint.
    virtual void
    serialize(Archive &archive) = 0;

    /**
     * A distance the focus may travel, from where it is now, before
     * minimum_error(@p center, @p radius) can cross @p error in either direction
     * (a lower bound; 0, the default, means "unknown: check every time"). A query
     * must change only through set_focus() once it is used for extraction: a Lod
     * relies on this to skip the nodes whose answer cannot have changed.
     */
    virtual double
    focus_slack(const mesh::Point3 &center, double radius, double error) const;

    /// A number no other query object made in this process has (Lod uses it to notice
    /// that it is given a different query).
    std::uint64_t
    identity() const
    {
      return id;
    }

    /**
     * The smallest error the query allows in the ball of @p center and @p radius. It
     * must not increase when the ball grows, which makes extraction unique.
     */
    virtual double
    minimum_error(const mesh::Point3 &center, double radius) const = 0;

    /// The error of a regular tetrahedron of edge @p h.
    static double
    error_of_cell_size(double h);

  private:
    static std::uint64_t
    next_identity();

    std::uint64_t id = next_identity();
  };

  /// The registry of level of detail queries.
  using LodQueryRegistry = PluginRegistry<LodQuery>;
} // namespace lacerta::mt

/// Registers a level of detail query plugin.
#define LACERTA_REGISTER_LOD_QUERY(classname, name, description) \
  LACERTA_REGISTER_PLUGIN(lacerta::mt::LodQuery, classname, name, description)
