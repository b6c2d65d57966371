/**
 * @file
 * A picture of the simulated tissue with VTK: for the `png` postprocessor (offscreen)
 * and for lacerta-view (on screen).
 */
#pragma once

#include <lacerta/cut/tool.h>
#include <lacerta/view/surface_field.h>

#include <vtkNew.h>
#include <vtkSmartPointer.h>

#include <array>
#include <optional>
#include <string>

class vtkActor;
class vtkPolyData;
class vtkPolyDataMapper;
class vtkRenderer;
class vtkRenderWindow;
class vtkScalarBarActor;
class vtkTextActor;
class vtkLineSource;

namespace lacerta::view
{
  /// Where the camera is; without a position it looks at the whole object from above,
  /// somewhat from the front (-y) and the left (-x).
  struct Camera
  {
    std::optional<std::array<double, 3>> position;
    std::array<double, 3>                focal_point{};
    std::array<double, 3>                view_up{{0, 0, 1}};
  };

  /**
   * The tissue's surface coloured by a field, with a colour bar, a title line, the
   * blade as a segment and, on request, the mesh's surface edges (the wireframe that
   * shows the level of detail). show() takes a new state; the renderer draws it in any
   * render window.
   */
  class ScenePicture
  {
  public:
    ScenePicture();
    ~ScenePicture();

    /**
     * Shows @p mesh at the positions of @p system, coloured by @p field, with the
     * blade @p blade (none: no blade) and the title @p title. The colours span
     * @p range if given, the field's range otherwise.
     */
    void
    show(const mesh::TetMesh                        &mesh,
         const physics::ParticleSystem              &system,
         Field                                       field,
         const std::optional<cut::Blade>            &blade,
         const std::string                          &title,
         const std::optional<std::array<double, 2>> &range = std::nullopt);

    /**
     * Shows @p surface (made by surface_with_field() for @p field), with the blade
     * @p blade and the title @p title, coloured over @p range if given.
     */
    void
    show_surface(vtkPolyData                                *surface,
                 Field                                       field,
                 const std::optional<cut::Blade>            &blade,
                 const std::string                          &title,
                 const std::optional<std::array<double, 2>> &range = std::nullopt);

    /// The actor of the tissue's surface (for picking).
    vtkActor *
    surface();

    /// Draws the surface's edges over it (or not).
    void
    set_wireframe(bool on);

    /// Puts the camera at @p camera; without a position, fits the object in view.
    void
    set_camera(const Camera &camera);

    /// The renderer to add to a render window.
    vtkRenderer *
    renderer();

    /// The text at the top left (the viewer's heads-up line); empty hides it.
    void
    set_status(const std::string &text);

  private:
    /// The edges of the surface shown, for the wireframe.
    void
    update_edges();

    vtkNew<vtkRenderer>          renderer_;
    vtkSmartPointer<vtkPolyData> shown;
    vtkNew<vtkPolyDataMapper>    surface_mapper;
    vtkNew<vtkActor>             surface_actor;
    vtkNew<vtkActor>             edge_actor;
    vtkNew<vtkPolyDataMapper>    edge_mapper;
    vtkNew<vtkLineSource>        blade_line;
    vtkNew<vtkActor>             blade_actor;
    vtkNew<vtkScalarBarActor>    colour_bar;
    vtkNew<vtkTextActor>         title_text;
    vtkNew<vtkTextActor>         status_text;
    bool                         camera_set = false;
  };

  /// The PNG bytes of what @p window shows.
  std::string
  png_of_window(vtkRenderWindow *window);
} // namespace lacerta::view
