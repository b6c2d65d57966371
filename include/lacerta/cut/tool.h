/**
 * @file
 * Cutting tools (plugins, `subsection Tool`): where the scalpel's blade is at any time.
 */
#pragma once

#include <lacerta/base/plugins.h>
#include <lacerta/cut/geometry.h>

#include <memory>
#include <string>

namespace lacerta::cut
{
  /**
   * The scalpel's cutting edge, a segment from its tail to its head (paper, Section 6),
   * in world coordinates: it cuts the deformed tissue where the user sees it.
   */
  struct Blade
  {
    Point tail{};
    Point head{};
  };

  /**
   * A tool moves a blade in time. The scene asks it for the blade at the end of every
   * step and hands the motion to the Cutter; an interactive driver skips the tool and
   * calls Cutter::move_blade() itself.
   */
  class Tool
  {
  public:
    /// Kind name used in messages and in the documentation.
    static std::string
    plugin_kind()
    {
      return "tool";
    }

    virtual ~Tool() = default;

    /// Reads the plugin's parameters from its subsection.
    virtual void
    parse_parameters(dealii::ParameterHandler &prm) = 0;

    /// The blade at time @p t.
    virtual Blade
    blade(double t) const = 0;

    /**
     * Declares `subsection Tool` with the `Type` selector (`none` or a plugin) and the
     * plugins' subsections.
     */
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    /// Creates the selected tool, or nothing for `none` (then no cut structure exists).
    static std::unique_ptr<Tool>
    create(dealii::ParameterHandler &prm);
  };

  /// The registry of tools.
  using ToolRegistry = PluginRegistry<Tool>;
} // namespace lacerta::cut

/// Registers a tool plugin.
#define LACERTA_REGISTER_TOOL(classname, name, description) \
  LACERTA_REGISTER_PLUGIN(lacerta::cut::Tool, classname, name, description)
