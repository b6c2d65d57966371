/**
 * @file
 * The connection to the X display that VTK renders on.
 */
#pragma once

#include <string>

class vtkRenderWindow;

namespace lacerta::view
{
  /**
   * A connection to the X display named by DISPLAY, opened by Lacerta and handed to
   * VTK's render windows (Debian's VTK renders through X, even offscreen). Opening it
   * here, with a few retries, lets a virtual display that is busy for a moment (Xvfb
   * on a loaded machine) answer the next attempt, where VTK's own single attempt
   * aborted the program.
   */
  class XDisplay
  {
  public:
    /**
     * Opens the display. Throws an Error if there is none, naming @p who (what needs
     * it) and saying to run under `xvfb-run -a` on a machine without a screen.
     */
    explicit XDisplay(const std::string &who);

    /// Closes the connection (after the windows that use it are gone).
    ~XDisplay();

    XDisplay(const XDisplay &) = delete;
    XDisplay &
    operator=(const XDisplay &) = delete;

    /// Makes @p window render on this connection.
    void
    attach(vtkRenderWindow &window) const;

  private:
    /// The Xlib Display.
    void *display = nullptr;
  };
} // namespace lacerta::view
