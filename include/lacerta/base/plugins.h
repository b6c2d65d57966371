/**
 * @file
 * Plugins by name, in the manner of ASPECT: every kind of plugin (integrator, force
 * model, mesh source, region, constraint, body force, postprocessor) has an Interface
 * class and a registry; a plugin registers itself with a macro, and the selector entry
 * of the parameter file is a Patterns::Selection built from the registry, documented
 * with every plugin's description.
 */
#pragma once

#include <lacerta/base/exceptions.h>

#include <deal.II/base/parameter_handler.h>

#include <functional>
#include <map>
#include <memory>
#include <string>

namespace lacerta
{
  /**
   * The registry of the plugins of one kind, whose base class is @p InterfaceType.
   * InterfaceType must have a static `plugin_kind()` returning the kind's name (used in
   * messages) and virtual `declare_parameters`-style hooks of its own.
   */
  template <typename InterfaceType>
  class PluginRegistry
  {
  public:
    /**
     * What the registry knows of one plugin.
     */
    struct Entry
    {
      /// One-paragraph description, printed by `--help` and in the parameter docs.
      std::string description;
      /// Declares the plugin's own parameters in the current subsection.
      std::function<void(dealii::ParameterHandler &)> declare_parameters;
      /// Creates a new instance.
      std::function<std::unique_ptr<InterfaceType>()> create;
    };

    /**
     * Registers a plugin; called at library load time by the registration macros.
     */
    static void
    register_plugin(const std::string &name, Entry entry)
    {
      entries()[name] = std::move(entry);
    }

    /**
     * All plugins of this kind, sorted by name.
     */
    static const std::map<std::string, Entry> &
    plugins()
    {
      return entries();
    }

    /**
     * The names of all plugins, separated by '|', for Patterns::Selection.
     */
    static std::string
    selection_pattern()
    {
      std::string names;
      for (const auto &[name, entry] : entries())
        names += (names.empty() ? "" : "|") + name;
      return names;
    }

    /**
     * A documentation string that lists every plugin with its description.
     */
    static std::string
    documentation(const std::string &preamble)
    {
      std::string text = preamble + " The following plugins are available:";
      for (const auto &[name, entry] : entries())
        text += "\n\n`" + name + "': " + entry.description;
      return text;
    }

    /**
     * Declares a selector entry @p entry_name whose value is one plugin name.
     */
    static void
    declare_selector(dealii::ParameterHandler &prm,
                     const std::string        &entry_name,
                     const std::string        &default_name,
                     const std::string        &preamble)
    {
      prm.declare_entry(entry_name,
                        default_name,
                        dealii::Patterns::Selection(selection_pattern()),
                        documentation(preamble));
    }

    /**
     * Declares a list entry @p entry_name whose value is a list of plugin names.
     */
    static void
    declare_list(dealii::ParameterHandler &prm,
                 const std::string        &entry_name,
                 const std::string        &default_names,
                 const std::string        &preamble)
    {
      prm.declare_entry(entry_name,
                        default_names,
                        dealii::Patterns::MultipleSelection(selection_pattern()),
                        documentation(preamble));
    }

    /**
     * The subsection that holds the parameters of plugin @p name: its name with the
     * first letter capitalised (plugin `file` reads `subsection File`).
     */
    static std::string
    subsection_name(std::string name)
    {
      if (!name.empty() && name[0] >= 'a' && name[0] <= 'z')
        name[0] = static_cast<char>(name[0] - 'a' + 'A');
      return name;
    }

    /**
     * Declares the parameters of every plugin, each in its subsection_name().
     */
    static void
    declare_all_in_subsections(dealii::ParameterHandler &prm)
    {
      for (const auto &[name, entry] : entries())
      {
        prm.enter_subsection(subsection_name(name));
        entry.declare_parameters(prm);
        prm.leave_subsection();
      }
    }

    /**
     * Creates the plugin called @p name; an unknown name is an Error.
     */
    static std::unique_ptr<InterfaceType>
    create(const std::string &name)
    {
      const auto found = entries().find(name);
      if (found == entries().end())
        throw_error("Unknown ",
                    InterfaceType::plugin_kind(),
                    " '",
                    name,
                    "'. Known: ",
                    selection_pattern(),
                    ".");
      return found->second.create();
    }

    /**
     * Declares `subsection @p subsection` holding the selector @p entry_name and the
     * subsections of every plugin: the layout of a kind that has one active plugin.
     */
    static void
    declare_selector_subsection(dealii::ParameterHandler &prm,
                                const std::string        &subsection,
                                const std::string        &entry_name,
                                const std::string        &default_name,
                                const std::string        &preamble)
    {
      prm.enter_subsection(subsection);
      declare_selector(prm, entry_name, default_name, preamble);
      declare_all_in_subsections(prm);
      prm.leave_subsection();
    }

    /**
     * Creates the plugin selected by @p entry_name in `subsection @p subsection`, with
     * its parameters read.
     */
    static std::unique_ptr<InterfaceType>
    create_selected(dealii::ParameterHandler &prm,
                    const std::string        &subsection,
                    const std::string        &entry_name)
    {
      prm.enter_subsection(subsection);
      std::unique_ptr<InterfaceType> plugin = create_and_parse(prm.get(entry_name), prm);
      prm.leave_subsection();
      return plugin;
    }

    /**
     * Creates plugin @p name and lets it read its parameters from its subsection of the
     * current subsection.
     */
    static std::unique_ptr<InterfaceType>
    create_and_parse(const std::string &name, dealii::ParameterHandler &prm)
    {
      std::unique_ptr<InterfaceType> plugin = create(name);
      prm.enter_subsection(subsection_name(name));
      plugin->parse_parameters(prm);
      prm.leave_subsection();
      return plugin;
    }

  private:
    static std::map<std::string, Entry> &
    entries()
    {
      static std::map<std::string, Entry> registered;
      return registered;
    }
  };


  /**
   * Registers a plugin class at load time; used by the LACERTA_REGISTER_* macros.
   */
  template <typename InterfaceType, typename PluginType>
  struct PluginRegistrar
  {
    PluginRegistrar(const std::string &name, const std::string &description)
    {
      PluginRegistry<InterfaceType>::register_plugin(
        name,
        {description,
         [](dealii::ParameterHandler &prm) { PluginType::declare_parameters(prm); },
         []() -> std::unique_ptr<InterfaceType>
         { return std::make_unique<PluginType>(); }});
    }
  };
} // namespace lacerta

/**
 * Registers @p classname as a plugin of kind @p interface under @p name. The class must
 * be default constructible and have a static `declare_parameters(ParameterHandler &)`.
 */
#define LACERTA_REGISTER_PLUGIN(interface, classname, name, description) \
  static const lacerta::PluginRegistrar<interface, classname>            \
    lacerta_plugin_registrar_##classname(name, description)
