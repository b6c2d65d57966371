#include <lacerta/base/exceptions.h>
#include <lacerta/base/output_file.h>
#include <lacerta/cut/geometry.h>
#include <lacerta/mesh/tet_mesh.h>
#include <lacerta/physics/particle_system.h>
#include <lacerta/postprocess/postprocessor.h>
#include <lacerta/scene/scene.h>
#include <lacerta/simulator/simulator.h>
#include <lacerta/view/scene_picture.h>
#include <lacerta/view/viewer.h>
#include <lacerta/view/x_display.h>

#include <vtkActor.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCellPicker.h>
#include <vtkCommand.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkObjectFactory.h>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace lacerta::view
{
  namespace
  {
    using Clock = std::chrono::steady_clock;

    double
    seconds_since(const Clock::time_point start)
    {
      return std::chrono::duration<double>(Clock::now() - start).count();
    }


    /**
     * The mouse and keys of lacerta-view: the left button cuts where it goes down on
     * the tissue (beside it, nothing); with Ctrl or Shift it turns the camera, as do
     * the middle and right buttons (pan, zoom) as usual. The viewer's keys are its own,
     * the others VTK's.
     */
    class ScalpelStyle : public vtkInteractorStyleTrackballCamera
    {
    public:
      static ScalpelStyle *
      New();
      vtkTypeMacro(ScalpelStyle, vtkInteractorStyleTrackballCamera);

      Viewer *viewer = nullptr;

      void
      OnLeftButtonDown() override
      {
        vtkRenderWindowInteractor *i = GetInteractor();
        if (i->GetControlKey() || i->GetShiftKey())
          vtkInteractorStyleTrackballCamera::OnLeftButtonDown();
        else
          viewer->press(i->GetEventPosition()[0], i->GetEventPosition()[1]);
      }

      void
      OnMouseMove() override
      {
        if (viewer->cutting())
          viewer->drag(GetInteractor()->GetEventPosition()[0],
                       GetInteractor()->GetEventPosition()[1]);
        else
          vtkInteractorStyleTrackballCamera::OnMouseMove();
      }

      void
      OnLeftButtonUp() override
      {
        if (viewer->cutting())
          viewer->release();
        else
          vtkInteractorStyleTrackballCamera::OnLeftButtonUp();
      }

      void
      OnChar() override
      {
        if (!viewer->key(GetInteractor()->GetKeyCode()))
          vtkInteractorStyleTrackballCamera::OnChar();
      }
    };
    vtkStandardNewMacro(ScalpelStyle);


    void
    on_timer(vtkObject *, unsigned long, void *viewer, void *timer_id)
    {
      static_cast<Viewer *>(viewer)->timer(*static_cast<int *>(timer_id));
    }
  } // namespace


  /// A state of the simulation, ready to draw.
  struct Viewer::Snapshot
  {
    vtkSmartPointer<vtkPolyData> surface;
    Field                        field = Field::displacement;
    std::optional<cut::Blade>    blade;
    double                       time = 0, real_time_factor = 0, cut_step_ms = 0;
    unsigned int                 tets = 0, particles = 0, substeps = 1;
    bool                         finished = false;
  };


  void
  Viewer::declare_parameters(dealii::ParameterHandler &prm)
  {
    prm.enter_subsection("Viewer");
    MouseScalpel::declare_parameters(prm);
    prm.declare_entry("Field",
                      "displacement",
                      dealii::Patterns::Selection(field_names()),
                      "What colours the surface when lacerta-view starts ('f' "
                      "switches).");
    prm.declare_entry("Speed",
                      "1",
                      dealii::Patterns::Double(0, 1000),
                      "Simulated seconds per wall-clock second lacerta-view aims at "
                      "('+' and '-' double and halve it); 0: as fast as it can.");
    prm.declare_entry("Frames per second",
                      "30",
                      dealii::Patterns::Double(1, 240),
                      "How often lacerta-view draws a new state.");
    prm.leave_subsection();
  }


  Viewer::Viewer(const Options &options_in)
      : options(options_in)
  {
    Simulator::read_parameters(options.scene_file, prm);
    if (prm.get("Mode") != "simulation")
      throw_error("lacerta-view runs scenes in 'Mode = simulation'; '",
                  options.scene_file,
                  "' sets 'Mode = ",
                  prm.get("Mode"),
                  "'.");
    prm.enter_subsection("Viewer");
    blade_parameters  = MouseScalpel::parse_parameters(prm);
    field             = static_cast<int>(field_from_name(prm.get("Field")));
    speed             = prm.get_double("Speed");
    frames_per_second = prm.get_double("Frames per second");
    prm.leave_subsection();
    // The viewer runs until it is closed, writes no files of the scene's, and holds
    // a scalpel even in a scene without one.
    prm.set("End time", "10000");
    prm.enter_subsection("Postprocess");
    prm.set("List of postprocessors", "");
    prm.leave_subsection();
    if (options.benchmark)
    {
      if (!options.events_file.empty())
        throw_error("lacerta-view: --benchmark runs its own stroke; it cannot take "
                    "--events as well.");
      // Real time, as a user sees it, drawing as often as the window can.
      speed             = 1;
      frames_per_second = 120;
      std::istringstream script(benchmark_events());
      parse_events(script, "the benchmark's stroke");
      // The benchmark's events come on the wall clock, like a hand's: the
      // simulation never waits for them.
      next_event_time = 1e300;
    }
    else if (!options.events_file.empty())
      read_events();
  }


  std::string
  Viewer::benchmark_events()
  {
    std::ostringstream script;
    script << "0.5 press 0.3 0.5\n";
    for (unsigned int k = 1; k <= 50; ++k)
      script << 0.5 + 0.02 * k << " move " << 0.3 + 0.4 * k / 50 << " 0.5\n";
    script << "1.5 release\n2 quit\n";
    return script.str();
  }


  Viewer::~Viewer()
  {
    stop_simulation();
  }


  void
  Viewer::read_events()
  {
    std::ifstream in(options.events_file);
    if (!in)
      throw_error("Events file '", options.events_file, "' cannot be opened.");
    parse_events(in, "Events file '" + options.events_file + "'");
  }


  void
  Viewer::parse_events(std::istream &in, const std::string &source)
  {
    std::string line;
    for (unsigned int number = 1; std::getline(in, line); ++number)
    {
      std::istringstream words(line.substr(0, line.find('#')));
      Event              event;
      if (!(words >> event.time))
        continue;
      words >> event.what;
      for (std::string word; words >> word;)
        event.arguments.push_back(word);
      const std::size_t n = event.arguments.size();
      const bool        good =
        ((event.what == "press" || event.what == "move") && n == 2)
        || ((event.what == "release" || event.what == "quit") && n == 0)
        || ((event.what == "key" || event.what == "screenshot") && n == 1);
      if (!good || (!events.empty() && event.time < events.back().time))
        throw_error(source,
                    ", line ",
                    number,
                    ": expected 'time press|move u v', 'time release', 'time key c', "
                    "'time screenshot file' or 'time quit', in time order.");
      events.push_back(event);
    }
    if (!events.empty())
      next_event_time = events[0].time;
  }


  void
  Viewer::start_simulation()
  {
    // A scene without a tool gets a scalpel waiting above the object, so that the
    // mouse has a cutter to hold: the object's size comes from the scene built once
    // without it.
    prm.enter_subsection("Tool");
    const bool has_tool = prm.get("Type") != "none";
    prm.leave_subsection();
    // The level of detail follows the scalpel, wherever the mouse takes it.
    const auto follow_the_tool = [this]
    {
      prm.enter_subsection("Multiresolution");
      prm.set("Focus follows", "tool");
      prm.leave_subsection();
    };
    if (has_tool)
      follow_the_tool();
    simulator = std::make_unique<Simulator>(prm, options.scene_file);
    cut::Box box;
    for (const mesh::Point3 &x : simulator->get_scene().active_mesh().get_vertices())
      box.extend(x);
    object_size = mesh::distance(box.lower, box.upper);
    if (!has_tool)
    {
      const double z = box.upper[2] + object_size + blade_parameters.length;
      const double x = 0.5 * (box.lower[0] + box.upper[0]),
                   y = 0.5 * (box.lower[1] + box.upper[1]);
      std::ostringstream keys;
      keys << std::setprecision(17);
      for (const double t : {0.0, 1.0})
        keys << (t > 0 ? "; " : "") << t << ", " << x << ", " << y << ", "
             << z + blade_parameters.length << ", " << x << ", " << y << ", " << z;
      prm.enter_subsection("Tool");
      prm.set("Type", "scalpel");
      prm.enter_subsection("Scalpel");
      prm.set("Keyframes", keys.str());
      prm.leave_subsection();
      prm.leave_subsection();
      follow_the_tool();
      simulator = std::make_unique<Simulator>(prm, options.scene_file);
    }
    scalpel = std::make_unique<MouseScalpel>(blade_parameters, object_size);
    stop    = false;
    simulator->signals.blade     = [this](const double t) { return scalpel->blade(t); };
    simulator->signals.stop      = [this] { return stop.load(); };
    auto       wall_start        = std::make_shared<Clock::time_point>(Clock::now());
    auto       sim_start         = std::make_shared<double>(-1.0);
    auto       last_frame        = std::make_shared<Clock::time_point>(Clock::now());
    auto       last_time         = std::make_shared<double>(0.0);
    const auto paced_speed       = std::make_shared<double>(speed.load());
    simulator->signals.post_step = [=](const postprocess::RunState &s)
    {
      if (s.blade != nullptr)
        scalpel->used(s.time, *s.blade);
      if (bench.measuring)
      {
        // Read by print_benchmark() once this thread has ended.
        if (bench.first_time < 0)
        {
          bench.wall_start = Clock::now();
          bench.first_time = s.time;
        }
        else
          bench.busy_seconds += s.step_seconds;
        bench.last_time    = s.time;
        bench.wall_seconds = seconds_since(bench.wall_start);
        bench.cut_steps += s.cut_tets > 0 ? 1 : 0;
        bench.cut_tets += s.cut_tets;
        bench.largest_cut_step = std::max(bench.largest_cut_step, s.cut_step_seconds);
        bench.tets             = s.mesh->n_tets();
      }
      // Real time: wait until the wall clock has caught up with the simulation.
      if (*sim_start < 0 || *paced_speed != speed || paused)
      {
        std::unique_lock<std::mutex> lock(mutex);
        resume.wait(lock, [this] { return !paused || stop; });
        *wall_start  = Clock::now();
        *sim_start   = s.time;
        *paced_speed = speed;
      }
      if (*paced_speed > 0)
      {
        const double ahead =
          (s.time - *sim_start) / *paced_speed - seconds_since(*wall_start);
        if (ahead > 0)
          std::this_thread::sleep_for(std::chrono::duration<double>(ahead));
      }
      const double since   = seconds_since(*last_frame);
      const bool   waiting = s.time >= next_event_time;
      if (since < 1 / frames_per_second && !stop && !waiting)
        return;
      auto snapshot     = std::make_shared<Snapshot>();
      snapshot->field   = static_cast<Field>(field.load());
      snapshot->surface = surface_with_field(*s.mesh, *s.system, snapshot->field);
      snapshot->time    = s.time;
      snapshot->real_time_factor = (s.time - *last_time) / since;
      snapshot->cut_step_ms      = 1e3 * s.cut_step_seconds;
      snapshot->tets             = s.mesh->n_tets();
      snapshot->particles        = s.system->n_particles();
      snapshot->substeps         = s.substeps;
      if (s.blade != nullptr)
        snapshot->blade = *s.blade;
      *last_frame = Clock::now();
      *last_time  = s.time;
      std::unique_lock<std::mutex> lock(mutex);
      if (latest && snapshot->cut_step_ms == 0)
        snapshot->cut_step_ms = latest->cut_step_ms;
      latest = snapshot;
      if (waiting)
      {
        resume.wait(lock, [&] { return s.time < next_event_time || stop; });
        *wall_start = Clock::now();
        *sim_start  = s.time;
      }
    };
    error.clear();
    thread = std::thread([this] { simulate(); });
  }


  void
  Viewer::simulate()
  {
    try
    {
      simulator->run();
    }
    catch (const std::exception &e)
    {
      const std::lock_guard<std::mutex> lock(mutex);
      error = e.what();
    }
    const std::lock_guard<std::mutex> lock(mutex);
    auto                              done =
      latest ? std::make_shared<Snapshot>(*latest) : std::make_shared<Snapshot>();
    done->finished = true;
    latest         = done;
  }


  void
  Viewer::stop_simulation()
  {
    if (!thread.joinable())
      return;
    stop = true;
    resume.notify_all();
    thread.join();
  }


  std::array<double, 3>
  Viewer::on_plane(const int                    x,
                   const int                    y,
                   const std::array<double, 3> &origin,
                   const std::array<double, 3> &normal) const
  {
    vtkRenderer          *renderer = picture->renderer();
    std::array<double, 3> ends[2];
    for (int k = 0; k < 2; ++k)
    {
      renderer->SetDisplayPoint(x, y, k);
      renderer->DisplayToWorld();
      const double *w = renderer->GetWorldPoint();
      ends[k]         = {{w[0] / w[3], w[1] / w[3], w[2] / w[3]}};
    }
    const auto   ray   = mesh::sub(ends[1], ends[0]);
    const double along = mesh::dot(ray, normal);
    if (std::abs(along) < 1e-300)
      return origin;
    const double s = mesh::dot(mesh::sub(origin, ends[0]), normal) / along;
    return mesh::add(ends[0], mesh::scale(s, ray));
  }


  void
  Viewer::press(const int x, const int y)
  {
    vtkNew<vtkCellPicker> picker;
    picker->SetTolerance(0.0005);
    picker->PickFromListOn();
    picker->AddPickList(picture->surface());
    if (!picker->Pick(x, y, 0, picture->renderer()))
      return;
    picker->GetPickPosition(press_point.data());
    vtkCamera            *camera = picture->renderer()->GetActiveCamera();
    std::array<double, 3> eye;
    camera->GetPosition(eye.data());
    view_direction = mesh::normalized(mesh::sub(press_point, eye));
    scalpel->press(press_point, view_direction);
  }


  void
  Viewer::drag(const int x, const int y)
  {
    scalpel->drag(on_plane(x, y, press_point, view_direction));
  }


  void
  Viewer::release()
  {
    scalpel->release();
  }


  bool
  Viewer::cutting() const
  {
    return scalpel->held();
  }


  bool
  Viewer::key(const char key)
  {
    switch (key)
    {
      case ' ':
      case 'p':
        paused = !paused;
        resume.notify_all();
        return true;
      case 'r':
        stop_simulation();
        latest.reset();
        start_simulation();
        return true;
      case 's':
        screenshot();
        return true;
      case 'w':
        wireframe = !wireframe;
        picture->set_wireframe(wireframe);
        window->Render();
        return true;
      case 'f':
        field = (field + 1) % 3;
        return true;
      case '-':
        speed = speed / 2;
        return true;
      case '+':
      case '=':
        speed = speed > 0 ? speed * 2 : 1;
        return true;
      case 'q':
        stop_simulation();
        interactor->TerminateApp();
        return true;
      default:
        return false;
    }
  }


  void
  Viewer::screenshot(const std::string &file)
  {
    std::string name = file;
    if (name.empty())
    {
      char buffer[64];
      std::snprintf(buffer, sizeof(buffer), "screenshot-%03u.png", n_screenshots++);
      name = buffer;
    }
    window->Render();
    write_file_atomically(name, png_of_window(window), true);
    std::cout << "Screenshot: " << name << std::endl;
  }


  void
  Viewer::inject_events(const double simulated_time)
  {
    const int *size = window->GetSize();
    for (; next_event < events.size() && events[next_event].time <= simulated_time;
         ++next_event)
    {
      const Event &e = events[next_event];
      // --benchmark measures from the press to the release.
      if (options.benchmark && (e.what == "press" || e.what == "release"))
        bench.measuring = e.what == "press";
      if (e.what == "press" || e.what == "move")
      {
        // (u, v) in [0, 1] across the window, from its lower left corner.
        const int x = static_cast<int>(std::stod(e.arguments[0]) * size[0]);
        const int y = static_cast<int>(std::stod(e.arguments[1]) * size[1]);
        interactor->SetEventInformation(x, y, 0, 0);
        interactor->InvokeEvent(e.what == "press" ? vtkCommand::LeftButtonPressEvent
                                                  : vtkCommand::MouseMoveEvent);
      }
      else if (e.what == "release")
        interactor->InvokeEvent(vtkCommand::LeftButtonReleaseEvent);
      else if (e.what == "key")
      {
        interactor->SetKeyCode(e.arguments[0][0]);
        interactor->InvokeEvent(vtkCommand::CharEvent);
      }
      else if (e.what == "screenshot")
        screenshot(e.arguments[0]);
      else if (e.what == "quit")
      {
        next_event_time = 1e300;
        key('q');
        return;
      }
    }
    if (options.benchmark)
      return;
    {
      const std::lock_guard<std::mutex> lock(mutex);
      next_event_time = next_event < events.size() ? events[next_event].time : 1e300;
    }
    resume.notify_all();
  }


  void
  Viewer::frame()
  {
    std::shared_ptr<Snapshot> snapshot;
    std::string               problem;
    {
      const std::lock_guard<std::mutex> lock(mutex);
      snapshot = latest;
      problem  = error;
    }
    if (!snapshot || !snapshot->surface)
      return;
    // Drawing again a state already shown only costs the simulation (software
    // rendering shares its cores): only new states, and the status once a second.
    const bool events_due = snapshot->finished || snapshot->time >= next_event_time;
    if (snapshot == shown && !events_due && seconds_since(shown_at) < 1)
      return;
    if (snapshot != shown && bench.measuring)
      ++bench.frames;
    shown    = snapshot;
    shown_at = Clock::now();
    ++n_frames;
    if (seconds_since(fps_since) >= 1)
    {
      fps       = n_frames / seconds_since(fps_since);
      n_frames  = 0;
      fps_since = Clock::now();
    }
    std::ostringstream title;
    title << std::fixed << std::setprecision(3) << "t = " << snapshot->time << " s   "
          << field_title(snapshot->field);
    picture->show_surface(snapshot->surface,
                          snapshot->field,
                          snapshot->blade,
                          title.str());
    std::ostringstream status;
    status << std::setprecision(3) << fps << " frames/s   " << snapshot->real_time_factor
           << " x real time (aim " << speed << ")   " << snapshot->tets
           << " tetrahedra   " << snapshot->particles << " particles   "
           << snapshot->substeps << " sub-steps   last cut step " << snapshot->cut_step_ms
           << " ms" << (paused ? "   PAUSED" : "")
           << (problem.empty() ? "" : "\nStopped: " + problem);
    picture->set_status(status.str());
    window->Render();
    if (!options.benchmark)
      inject_events(snapshot->finished ? 1e300 : snapshot->time);
    if (snapshot->finished && !problem.empty() && exit_code == 0)
    {
      exit_code = 1;
      std::cerr << "Error: " << problem << std::endl;
    }
  }


  void
  Viewer::timer(const int id)
  {
    if (id != event_timer)
    {
      frame();
      return;
    }
    if (options.benchmark)
    {
      // The stroke starts when the first state is on the screen.
      if (shown && bench.script_start == Clock::time_point())
        bench.script_start = Clock::now();
      if (bench.script_start != Clock::time_point())
        inject_events(seconds_since(bench.script_start));
      return;
    }
    bool events_due = false;
    {
      const std::lock_guard<std::mutex> lock(mutex);
      events_due = latest && (latest->finished || latest->time >= next_event_time);
    }
    if (events_due)
      frame();
  }


  int
  Viewer::run()
  {
    // Declared before the window, which must go first.
    const XDisplay display("lacerta-view");
    picture = std::make_unique<ScenePicture>();
    start_simulation();

    vtkNew<vtkRenderWindow> render_window;
    display.attach(*render_window);
    render_window->SetMultiSamples(0);
    render_window->SetSize(static_cast<int>(options.width),
                           static_cast<int>(options.height));
    render_window->SetWindowName(("lacerta-view " + options.scene_file).c_str());
    render_window->AddRenderer(picture->renderer());
    vtkNew<vtkRenderWindowInteractor> window_interactor;
    window_interactor->SetRenderWindow(render_window);
    vtkNew<ScalpelStyle> style;
    style->viewer = this;
    window_interactor->SetInteractorStyle(style);
    window     = render_window;
    interactor = window_interactor;
    window_interactor->Initialize();
    vtkNew<vtkCallbackCommand> timer;
    timer->SetCallback(on_timer);
    timer->SetClientData(this);
    window_interactor->AddObserver(vtkCommand::TimerEvent, timer);
    window_interactor->CreateRepeatingTimer(
      static_cast<unsigned long>(1000 / frames_per_second));
    // Scripted events are injected as soon as the simulation reaches them, not at the
    // next frame, so that a slow picture does not hold the simulation back.
    if (!events.empty())
      event_timer = window_interactor->CreateRepeatingTimer(2);
    window_interactor->Start();

    stop_simulation();
    if (options.benchmark && !print_benchmark() && exit_code == 0)
      exit_code = 1;
    if (!options.record_file.empty())
    {
      scalpel->write_record(options.record_file, options.scene_file);
      std::cout << "Recorded the stroke: " << options.record_file << std::endl;
    }
    const std::lock_guard<std::mutex> lock(mutex);
    if (!error.empty() && exit_code == 0)
    {
      std::cerr << "Error: " << error << std::endl;
      exit_code = 1;
    }
    window     = nullptr;
    interactor = nullptr;
    return exit_code;
  }


  bool
  Viewer::print_benchmark() const
  {
    if (bench.wall_seconds <= 0 || bench.busy_seconds <= 0)
    {
      std::cerr << "Error: lacerta-view --benchmark: the simulation made fewer than two "
                   "steps during the stroke; nothing was measured.\n";
      return false;
    }
    // The first step after the press starts the clocks.
    const double simulated = bench.last_time - bench.first_time;
    std::cout << std::setprecision(4)
              << "Benchmark stroke (1 s of dragging from t = " << bench.first_time
              << " s): " << simulated << " s simulated in " << bench.wall_seconds
              << " s: real-time factor " << simulated / bench.wall_seconds << " (aim 1); "
              << bench.frames << " states drawn: " << bench.frames / bench.wall_seconds
              << " frames per second (aim " << frames_per_second
              << "); the simulation's steps took " << bench.busy_seconds
              << " s: it could run " << simulated / bench.busy_seconds << " x real time; "
              << bench.cut_steps << " steps cut " << bench.cut_tets
              << " tetrahedra, the costliest cut step " << 1e3 * bench.largest_cut_step
              << " ms; " << bench.tets << " tetrahedra at the release\n";
    return true;
  }
} // namespace lacerta::view
