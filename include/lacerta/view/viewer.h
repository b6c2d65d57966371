/**
 * @file
 * lacerta-view: a scene in a VTK window, simulated in real time on a thread of its
 * own, cut with the mouse.
 */
#pragma once

#include <lacerta/view/mouse_scalpel.h>
#include <lacerta/view/surface_field.h>

#include <deal.II/base/parameter_handler.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

class vtkPolyData;
class vtkRenderWindow;
class vtkRenderWindowInteractor;

namespace lacerta
{
  class Simulator;
}

namespace lacerta::view
{
  class ScenePicture;

  /**
   * The interactive simulator. The simulation thread runs the scene's Simulator with
   * the blade from a MouseScalpel (SimulatorSignals), paced to a chosen multiple of
   * real time, and hands the viewer's thread a new surface at the frame rate; the
   * viewer's thread draws it and turns mouse and keys into blade motions and commands.
   * See doc/viewer.md for the keys.
   */
  class Viewer
  {
  public:
    /// What the command line chose.
    struct Options
    {
      /// The scene.
      std::string scene_file;
      /// Where to write the stroke as a parameter file at exit (empty: nowhere).
      std::string record_file;
      /// Events to inject, a file of lines 'time event ...' (empty: none).
      std::string events_file;
      /// Window size [pixels].
      unsigned int width = 1024, height = 768;
      /// Run the benchmark stroke (benchmark_events()) in real time at 60 frames per
      /// second and print the frame rate and real-time factor through it.
      bool benchmark = false;
    };

    /**
     * The scripted stroke of `--benchmark`, in wall-clock seconds from the first state
     * drawn: a press left of the window's middle at 0.5 s, a drag across 40 % of the
     * window for 1 s (one move every 20 ms), a release, and quit 0.5 s later.
     */
    static std::string
    benchmark_events();

    /// Declares `subsection Viewer`.
    static void
    declare_parameters(dealii::ParameterHandler &prm);

    explicit Viewer(const Options &options);
    ~Viewer();

    /// Opens the window and runs until it is closed or 'q' is pressed; returns the
    /// exit code (1 if the simulation stopped with an error).
    int
    run();

    /// Viewer thread: the left button went down at display position (@p x, @p y).
    void
    press(int x, int y);
    /// Viewer thread: the mouse moved to (@p x, @p y) with the left button down.
    void
    drag(int x, int y);
    /// Viewer thread: the left button went up.
    void
    release();
    /// Viewer thread: whether the scalpel is held.
    bool
    cutting() const;
    /// Viewer thread: the key @p key was pressed; false if it is not one of the
    /// viewer's.
    bool
    key(char key);
    /// Viewer thread: the timer @p id fired: the frame timer draws a frame, the
    /// events' timer draws one only if scripted events are due.
    void
    timer(int id);
    /// Viewer thread: draws the newest state if it is new (or a second has passed),
    /// with the status line, and injects the scripted events it has reached.
    void
    frame();

  private:
    /// What the simulation thread hands the viewer's thread.
    struct Snapshot;
    /// One scripted event.
    struct Event
    {
      double                   time;
      std::string              what;
      std::vector<std::string> arguments;
    };

    void
    start_simulation();
    void
    stop_simulation();
    /// The simulation thread's body.
    void
    simulate();
    /// Saves the window as a PNG file (@p file, or screenshot-NNN.png).
    void
    screenshot(const std::string &file = "");
    /// Where the view ray through display position (@p x, @p y) meets the plane
    /// through @p origin across @p normal.
    std::array<double, 3>
    on_plane(int                          x,
             int                          y,
             const std::array<double, 3> &origin,
             const std::array<double, 3> &normal) const;
    /// Reads the events file.
    void
    read_events();
    /// Injects the scripted events whose time has come.
    void
    inject_events(double simulated_time);
    /// Parses scripted events from @p in, read from @p source (for messages).
    void
    parse_events(std::istream &in, const std::string &source);
    /// Prints the figures of `--benchmark`; false (and a message) if the simulation
    /// made too few steps during the stroke to measure.
    bool
    print_benchmark() const;

    /**
     * What `--benchmark` measures between the stroke's press and its release: the
     * simulated and wall-clock span, the distinct states drawn, the simulation's own
     * time (its steps, without waiting or drawing) and the cut.
     */
    struct BenchmarkFigures
    {
      /// Between the press and the release (set by the viewer's thread).
      std::atomic<bool> measuring{false};
      /// When the script's clock started (the first state drawn).
      std::chrono::steady_clock::time_point script_start{};
      /// Simulated time of the first and of the last step measured.
      double       first_time = -1, last_time = 0;
      double       wall_seconds = 0, busy_seconds = 0, largest_cut_step = 0;
      unsigned int frames = 0, cut_steps = 0, cut_tets = 0, tets = 0;
      std::chrono::steady_clock::time_point wall_start;
    };

    Options                       options;
    dealii::ParameterHandler      prm;
    MouseScalpel::Parameters      blade_parameters;
    std::atomic<double>           speed{1};
    double                        frames_per_second = 30;
    std::atomic<int>              field{0};
    bool                          wireframe = false;
    std::unique_ptr<ScenePicture> picture;
    std::unique_ptr<MouseScalpel> scalpel;
    std::unique_ptr<Simulator>    simulator;
    std::thread                   thread;
    std::atomic<bool>             stop{false}, paused{false};
    std::mutex                    mutex;
    std::condition_variable       resume;
    std::shared_ptr<Snapshot>     latest;
    std::string                   error;
    double                        object_size = 1;
    std::array<double, 3>         press_point{}, view_direction{};
    unsigned int                  n_screenshots = 0, n_frames = 0;
    /// Frames per second, counted since `fps_since`.
    double                                fps       = 0;
    std::chrono::steady_clock::time_point fps_since = std::chrono::steady_clock::now();
    std::vector<Event>                    events;
    std::size_t                           next_event = 0;
    /// The time of the next scripted event: the simulation waits there until the
    /// viewer's thread has injected it, so that a script gives the same run each time.
    std::atomic<double>        next_event_time{1e300};
    vtkRenderWindow           *window     = nullptr;
    vtkRenderWindowInteractor *interactor = nullptr;
    int                        exit_code  = 0;
    /// The timer of the scripted events (-1: none).
    int              event_timer = -1;
    BenchmarkFigures bench;
    /// The state drawn last, and when.
    std::shared_ptr<Snapshot>             shown;
    std::chrono::steady_clock::time_point shown_at;
  };
} // namespace lacerta::view
