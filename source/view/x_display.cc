#include <lacerta/base/exceptions.h>
#include <lacerta/view/x_display.h>

#include <vtkRenderWindow.h>

#include <X11/Xlib.h>
#include <chrono>
#include <cstdlib>
#include <thread>

namespace lacerta::view
{
  XDisplay::XDisplay(const std::string &who)
  {
    const char *name = std::getenv("DISPLAY");
    const bool  set  = name != nullptr && *name != '\0';
    // A display that exists but is busy (a virtual one under load) is tried again
    // after a pause, 10 times over about 5 s in all.
    for (unsigned int attempt = 1; set && display == nullptr && attempt <= 10; ++attempt)
    {
      display = XOpenDisplay(nullptr);
      if (display == nullptr && attempt < 10)
        std::this_thread::sleep_for(std::chrono::milliseconds(100 * attempt));
    }
    if (display == nullptr)
      throw_error(who,
                  " needs an X display to render on (Debian's VTK renders through X, "
                  "even offscreen), and ",
                  !set ? std::string("DISPLAY is not set")
                       : "DISPLAY = '" + std::string(name) + "' cannot be opened",
                  ". On a machine without a screen, run under a virtual one: "
                  "xvfb-run -a <command>.");
  }


  XDisplay::~XDisplay()
  {
    if (display != nullptr)
      XCloseDisplay(static_cast<Display *>(display));
  }


  void
  XDisplay::attach(vtkRenderWindow &window) const
  {
    window.SetDisplayId(display);
  }
} // namespace lacerta::view
