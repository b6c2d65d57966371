#include <lacerta/base/exceptions.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/view/scene_picture.h>

#include <vtkActor.h>
#include <vtkAutoInit.h>
#include <vtkCamera.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkExtractEdges.h>
#include <vtkLineSource.h>
#include <vtkLookupTable.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include <cmath>

// VTK's implementations behind vtkRenderWindow, the text and the interactor styles,
// registered here rather than by CMake's vtk_module_autoinit(), which would put its
// definitions on every file of the library.
VTK_MODULE_INIT(vtkRenderingOpenGL2);
VTK_MODULE_INIT(vtkRenderingFreeType);
VTK_MODULE_INIT(vtkInteractionStyle);
VTK_MODULE_INIT(vtkRenderingUI);

namespace lacerta::view
{
  ScenePicture::ScenePicture()
  {
    renderer_->SetBackground(1, 1, 1);
    renderer_->SetBackground2(0.78, 0.82, 0.9);
    renderer_->GradientBackgroundOn();

    vtkNew<vtkLookupTable> colours;
    colours->SetHueRange(0.667, 0.0); // blue (low) to red (high)
    colours->Build();
    surface_mapper->SetLookupTable(colours);
    surface_mapper->SetColorModeToMapScalars();
    surface_mapper->ScalarVisibilityOn();
    surface_actor->SetMapper(surface_mapper);
    renderer_->AddActor(surface_actor);

    edge_mapper->ScalarVisibilityOff();
    edge_actor->SetMapper(edge_mapper);
    edge_actor->GetProperty()->SetColor(0.1, 0.1, 0.1);
    edge_actor->GetProperty()->SetLineWidth(1);
    edge_actor->VisibilityOff();
    renderer_->AddActor(edge_actor);

    vtkNew<vtkPolyDataMapper> blade_mapper;
    blade_mapper->SetInputConnection(blade_line->GetOutputPort());
    blade_actor->SetMapper(blade_mapper);
    blade_actor->GetProperty()->SetColor(0.2, 0.2, 0.2);
    blade_actor->GetProperty()->SetLineWidth(4);
    blade_actor->VisibilityOff();
    renderer_->AddActor(blade_actor);

    colour_bar->SetLookupTable(colours);
    colour_bar->SetNumberOfLabels(5);
    colour_bar->SetWidth(0.08);
    colour_bar->SetHeight(0.6);
    colour_bar->SetPosition(0.9, 0.2);
    colour_bar->GetLabelTextProperty()->SetColor(0, 0, 0);
    colour_bar->GetTitleTextProperty()->SetColor(0, 0, 0);
    colour_bar->SetLabelFormat("%-#6.3g");
    renderer_->AddActor2D(colour_bar);

    title_text->GetTextProperty()->SetColor(0, 0, 0);
    title_text->GetTextProperty()->SetFontSize(18);
    title_text->SetPosition(10, 10);
    renderer_->AddActor2D(title_text);
    status_text->GetTextProperty()->SetColor(0, 0, 0);
    status_text->GetTextProperty()->SetFontSize(14);
    status_text->GetTextProperty()->SetVerticalJustificationToTop();
    status_text->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    status_text->SetPosition(0.01, 0.98);
    renderer_->AddActor2D(status_text);
  }


  ScenePicture::~ScenePicture() = default;


  void
  ScenePicture::show(const mesh::TetMesh                        &mesh,
                     const physics::ParticleSystem              &system,
                     const Field                                 field,
                     const std::optional<cut::Blade>            &blade,
                     const std::string                          &title,
                     const std::optional<std::array<double, 2>> &range)
  {
    show_surface(surface_with_field(mesh, system, field), field, blade, title, range);
  }


  void
  ScenePicture::show_surface(vtkPolyData                                *surface,
                             const Field                                 field,
                             const std::optional<cut::Blade>            &blade,
                             const std::string                          &title,
                             const std::optional<std::array<double, 2>> &range)
  {
    surface_mapper->SetInputData(surface);
    if (field == Field::displacement)
      surface_mapper->SetScalarModeToUsePointData();
    else
      surface_mapper->SetScalarModeToUseCellData();
    vtkDataArray *values  = field == Field::displacement
                              ? surface->GetPointData()->GetScalars()
                              : surface->GetCellData()->GetScalars();
    double        span[2] = {0, 1};
    if (range)
    {
      span[0] = (*range)[0];
      span[1] = (*range)[1];
    }
    else if (values != nullptr && values->GetNumberOfTuples() > 0)
      values->GetRange(span);
    if (!(span[1] > span[0]))
      span[1] = span[0] + (span[0] != 0 ? 1e-6 * std::abs(span[0]) : 1e-12);
    surface_mapper->SetScalarRange(span);
    colour_bar->SetTitle(field_title(field).c_str());

    shown = surface;
    if (edge_actor->GetVisibility())
      update_edges();

    if (blade)
    {
      blade_line->SetPoint1(blade->tail.data());
      blade_line->SetPoint2(blade->head.data());
      blade_actor->VisibilityOn();
    }
    else
      blade_actor->VisibilityOff();
    title_text->SetInput(title.c_str());
    if (!camera_set)
      set_camera(Camera());
  }


  vtkActor *
  ScenePicture::surface()
  {
    return surface_actor;
  }


  void
  ScenePicture::set_wireframe(const bool on)
  {
    edge_actor->SetVisibility(on);
    if (on)
      update_edges();
  }


  void
  ScenePicture::update_edges()
  {
    if (shown == nullptr)
      return;
    vtkNew<vtkExtractEdges> edges;
    edges->SetInputData(shown);
    edges->Update();
    edge_mapper->SetInputData(edges->GetOutput());
  }


  void
  ScenePicture::set_camera(const Camera &camera)
  {
    camera_set        = true;
    vtkCamera *vtkcam = renderer_->GetActiveCamera();
    if (camera.position)
    {
      vtkcam->SetPosition(camera.position->data());
      vtkcam->SetFocalPoint(camera.focal_point.data());
      vtkcam->SetViewUp(camera.view_up.data());
      renderer_->ResetCameraClippingRange();
      return;
    }
    // Fit the object, seen from above, a little from the front and the left.
    double bounds[6];
    surface_actor->GetBounds(bounds);
    if (!(bounds[1] >= bounds[0]))
      return;
    const double centre[3] = {0.5 * (bounds[0] + bounds[1]),
                              0.5 * (bounds[2] + bounds[3]),
                              0.5 * (bounds[4] + bounds[5])};
    vtkcam->SetFocalPoint(centre);
    vtkcam->SetPosition(centre[0] - 0.3, centre[1] - 0.9, centre[2] + 1.2);
    vtkcam->SetViewUp(0, 0, 1);
    renderer_->ResetCamera(bounds);
  }


  vtkRenderer *
  ScenePicture::renderer()
  {
    return renderer_;
  }


  void
  ScenePicture::set_status(const std::string &text)
  {
    status_text->SetInput(text.c_str());
  }


  std::string
  png_of_window(vtkRenderWindow *window)
  {
    vtkNew<vtkWindowToImageFilter> grab;
    grab->SetInput(window);
    grab->ReadFrontBufferOff();
    grab->Update();
    vtkNew<vtkPNGWriter> writer;
    writer->SetInputConnection(grab->GetOutputPort());
    writer->WriteToMemoryOn();
    writer->Write();
    vtkUnsignedCharArray *bytes = writer->GetResult();
    if (bytes == nullptr || bytes->GetNumberOfTuples() == 0)
      throw_error("VTK could not encode the picture as PNG.");
    return std::string(reinterpret_cast<const char *>(bytes->GetPointer(0)),
                       static_cast<std::size_t>(bytes->GetNumberOfTuples()));
  }


} // namespace lacerta::view
