// lacerta-view: runs a scene in a window, in real time, and cuts it with the mouse.

#include <lacerta/base/exceptions.h>
#include <lacerta/view/viewer.h>

#include <deal.II/base/exceptions.h>

#include <cstdio>
#include <iostream>
#include <string>

namespace
{
  void
  usage(std::ostream &out)
  {
    out << "Usage: lacerta-view [--record stroke.prm] [--events events.txt] "
           "[--size WIDTHxHEIGHT] [--benchmark] scene.prm\n"
           "  Runs the scene in real time in a window; the left mouse button cuts "
           "(Ctrl or\n  Shift + left button, or a press beside the tissue, turns the "
           "camera).\n"
           "  Keys: space/p pause, r reset, s screenshot, w wireframe, f next field,\n"
           "        - slower, + faster, q quit (doc/viewer.md).\n"
           "  --record FILE  writes the blade's path at exit as a parameter file that\n"
           "                 replays it in batch: lacerta FILE\n"
           "  --events FILE  injects scripted mouse and key events (doc/viewer.md)\n"
           "  --benchmark    drags a scripted stroke across the middle of the window in\n"
           "                 real time and prints the frame rate and real-time factor\n";
  }
} // namespace


int
main(int argc, char **argv)
{
  // No MPI: the viewer runs simulations without postprocessors (Viewer), so nothing
  // of it uses MPI (Simulator::needs_mpi()).
  dealii::deal_II_exceptions::disable_abort_on_exception();
  dealii::deal_II_exceptions::suppress_stacktrace_in_exceptions();

  lacerta::view::Viewer::Options options;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h")
    {
      usage(std::cout);
      return 0;
    }
    if (arg == "--benchmark")
      options.benchmark = true;
    else if ((arg == "--record" || arg == "--events" || arg == "--size") && i + 1 < argc)
    {
      const std::string value = argv[++i];
      if (arg == "--record")
        options.record_file = value;
      else if (arg == "--events")
        options.events_file = value;
      else if (std::sscanf(value.c_str(), "%ux%u", &options.width, &options.height) != 2
               || options.width < 16 || options.height < 16 || options.width > 8192
               || options.height > 8192)
      {
        std::cerr << "Error: --size must be WIDTHxHEIGHT in pixels (16 to 8192), not '"
                  << value << "'.\n";
        return 2;
      }
    }
    else if (options.scene_file.empty() && arg.rfind("--", 0) != 0)
      options.scene_file = arg;
    else
    {
      usage(std::cerr);
      return 2;
    }
  }
  if (options.scene_file.empty())
  {
    usage(std::cerr);
    return 2;
  }

  return lacerta::run_reporting_errors(
    [&]
    {
      lacerta::view::Viewer viewer(options);
      return viewer.run();
    });
}
