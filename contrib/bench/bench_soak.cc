// lacerta-bench soak: many random scalpel strokes, partial and complete, some crossing
// earlier cuts, on the pulled slab of square_tear.prm with tears enabled and the
// invariants checked after every step; with the multiresolution model off and on.
// Every episode runs in a child process, so a crash is counted, not suffered. With
// --resume-check every completed episode is also stopped at a random step and resumed
// from its checkpoint, and must end bit for bit as it did.

#include <lacerta/base/exceptions.h>
#include <lacerta/base/output_file.h>
#include <lacerta/simulator/simulator.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/utilities.h>

#include "benchmark_registry.h"
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

namespace lacerta::bench
{
  namespace
  {
    using Clock   = std::chrono::steady_clock;
    using Seconds = std::chrono::duration<double>;

    /// What the soak is asked to do (the command line).
    struct SoakOptions
    {
      unsigned int strokes             = 10000;
      unsigned int strokes_per_episode = 5;
      unsigned int seed                = 1;
      bool         without_lod         = true;
      bool         with_lod            = true;
      std::string  directory           = "soak";
      /// Which outcomes make the exit code 1, indexed by Outcome (all but `completed`).
      std::vector<bool> fails = {false, true, true, true, true, true};
      /// Whether every completed episode is also stopped at a random step and resumed
      /// from its checkpoint, and must end bit for bit as it did uninterrupted.
      bool resume_check = false;
      /// Extra entries `Subsection/.../Entry=value` added to every episode.
      std::vector<std::string> settings;
    };


    /// `a/b/entry=value` as parameter-file lines.
    std::string
    settings_block(const std::string &setting)
    {
      const auto equals = setting.find('=');
      if (equals == std::string::npos)
        throw_error("soak: --set '", setting, "' is not 'Subsection/Entry=value'.");
      std::string path = setting.substr(0, equals), block, closing;
      std::size_t slash;
      while ((slash = path.find('/')) != std::string::npos)
      {
        block += "subsection " + path.substr(0, slash) + "\n";
        closing += "end\n";
        path = path.substr(slash + 1);
      }
      return block + "set " + path + " = " + setting.substr(equals + 1) + "\n" + closing;
    }

    /// A point of the blade's path in the slab's plane.
    struct PathPoint
    {
      double x = 0, y = 0;
    };

    /**
     * The blade's keyframes of one episode: strokes separated by lifts. A stroke starts
     * outside the slab with the blade down (it spans the slab's thickness with margin),
     * runs along a polyline, and ends outside (complete) or inside (partial); the blade
     * is then lifted above the tissue and moved, lifted, to the next start.
     */
    class EpisodeScript
    {
    public:
      explicit EpisodeScript(std::mt19937_64 &random)
          : random(random)
      {
      }

      /// Appends one random stroke; returns whether it was complete.
      bool
      add_stroke()
      {
        const bool             complete = uniform(0, 1) < 0.6;
        const PathPoint        start    = outside();
        std::vector<PathPoint> corners{start};
        // Through an earlier stroke's point a third of the time, so that cuts cross.
        const unsigned int n_inner = 1 + static_cast<unsigned int>(uniform(0, 3));
        for (unsigned int i = 0; i < n_inner; ++i)
          corners.push_back(
            !visited.empty() && uniform(0, 1) < 0.33
              ? visited[static_cast<std::size_t>(uniform(0, 1) * (visited.size() - 1e-9))]
              : inside());
        corners.push_back(complete ? outside() : inside());
        for (std::size_t i = 1; i + (complete ? 1 : 0) < corners.size(); ++i)
          visited.push_back(corners[i]);

        // A blade speed between a tenth of a cell and three cells per step.
        const double speed = std::exp(uniform(std::log(2.5), std::log(75.0)));
        move_to(start, false, 0.01);
        move_to(start, true, 0.005);
        for (std::size_t i = 1; i < corners.size(); ++i)
          move_to(corners[i],
                  true,
                  std::hypot(corners[i].x - corners[i - 1].x,
                             corners[i].y - corners[i - 1].y)
                    / speed);
        move_to(corners.back(), false, 0.005);
        // The tissue moves on for a while before the next stroke.
        move_to(corners.back(), false, uniform(0.005, 0.05));
        return complete;
      }

      /// The keyframes as the value of `Tool/Scalpel/Keyframes`.
      std::string
      keyframes() const
      {
        return text.str();
      }

      /// The time of the last keyframe [s].
      double
      end_time() const
      {
        return time;
      }

    private:
      double
      uniform(const double low, const double high)
      {
        return std::uniform_real_distribution<double>(low, high)(random);
      }

      // A point beyond the slab's edges (|x|, |y| <= 0.05 at rest, pulled outward in x
      // by up to 0.02 on each side).
      PathPoint
      outside()
      {
        const double angle = uniform(0, 2 * M_PI);
        const double reach = uniform(0.075, 0.09);
        return {reach * std::cos(angle), 0.08 * std::sin(angle)};
      }

      PathPoint
      inside()
      {
        return {uniform(-0.045, 0.045), uniform(-0.045, 0.045)};
      }

      // A keyframe @p duration after the previous one with the blade at @p p, down
      // through the tissue or lifted above it.
      void
      move_to(const PathPoint &p, const bool down, const double duration)
      {
        time += std::max(duration, 1e-4);
        const double head = down ? -0.03 : 0.05, tail = down ? 0.04 : 0.08;
        text.precision(17);
        text << (first ? "" : "; ") << time << ", " << p.x << ", " << p.y << ", " << tail
             << ", " << p.x << ", " << p.y << ", " << head;
        first = false;
      }

      std::mt19937_64       &random;
      std::ostringstream     text;
      std::vector<PathPoint> visited;
      double                 time  = 0;
      bool                   first = true;
    };

    /// The parameter file of one episode.
    std::string
    episode_parameters(std::mt19937_64                &random,
                       const unsigned int              n_strokes,
                       const bool                      lod,
                       const std::vector<std::string> &settings,
                       const bool                      resume_check,
                       unsigned int                   &complete)
    {
      EpisodeScript script(random);
      // The blade waits lifted at the start, away from the tissue.
      for (unsigned int s = 0; s < n_strokes; ++s)
        complete += script.add_stroke();
      const double pull = std::uniform_real_distribution<double>(0, 0.02)(random);

      std::ostringstream prm;
      prm.precision(17);
      prm << "# A soak episode of lacerta-bench soak: " << n_strokes
          << " random strokes on the pulled slab of square_tear.prm, tears on"
          << (lod ? ", on the multiresolution model" : "") << ".\n"
          << "include " << LACERTA_SOURCE_DIR << "/prm/square_tear.prm\n"
          << "set Output directory = output\n"
          << "set End time = " << script.end_time() << "\n"
          << "set Test mode = true\n"
          << "set Check invariants = true\n"
          << "subsection Constraints\n"
          << "  subsection left cube\n    subsection Moving handle\n"
          << "      set Displacement = -" << pull << "*min(t, 1); 0; 0\n"
          << "    end\n  end\n"
          << "  subsection right cube\n    subsection Moving handle\n"
          << "      set Displacement = " << pull << "*min(t, 1); 0; 0\n"
          << "    end\n  end\n"
          << "end\n"
          << "subsection Tool\n  set Type = scalpel\n  subsection Scalpel\n"
          << "    set Keyframes = " << script.keyframes() << "\n  end\nend\n"
          << "subsection Postprocess\n  set List of postprocessors ="
          << (resume_check ? " statistics, vtu" : "") << "\nend\n";
      if (lod)
        prm << "subsection Multiresolution\n"
            << "  set Enabled = true\n"
            << "  set Cache directory = " << std::filesystem::current_path().string()
            << "/mt-cache\n"
            << "  set Focus follows = tool\n"
            << "  set Re-extraction distance = 0.005\n"
            << "  set Query = focus\n"
            << "  subsection Focus\n    set Radius = 0.02\n"
            << "    set Cell size near the focus = 0\n"
            << "    set Cell size growth = 0.5\n  end\nend\n";
      for (const std::string &setting : settings)
        prm << settings_block(setting);
      return prm.str();
    }

    /// How one episode ended.
    enum class Outcome
    {
      completed,
      invariant_violation,
      blow_up,
      other_error,
      crash,
      /// Resumed from a checkpoint, the episode did not end as it did uninterrupted.
      resume_mismatch
    };

    /**
     * Runs the scene @p file in a child process, with its output sent to @p log. Returns
     * how it ended and, for an error, its message's first line in @p message.
     */
    Outcome
    run_episode(const std::string &file, const std::string &log, std::string &message)
    {
      int channel[2];
      if (::pipe(channel) != 0)
        throw_error("soak: cannot create a pipe: ", std::strerror(errno));
      std::fflush(stdout);
      const pid_t child = ::fork();
      if (child < 0)
        throw_error("soak: cannot start a process: ", std::strerror(errno));
      if (child == 0)
      {
        ::close(channel[0]);
        std::FILE *out  = std::freopen(log.c_str(), "w", stdout);
        int        code = out != nullptr ? 0 : 3;
        try
        {
          dealii::ParameterHandler prm;
          Simulator::read_parameters(file, prm);
          Simulator(prm, file).run();
        }
        catch (const std::exception &e)
        {
          const std::string what = e.what();
          code                   = what.find("Check invariants") != std::string::npos ? 1
                                   : what.find("blew up") != std::string::npos        ? 2
                                                                                      : 3;
          [[maybe_unused]] const auto written =
            ::write(channel[1], what.data(), what.size());
        }
        std::fflush(stdout);
        ::_exit(code);
      }
      ::close(channel[1]);
      char    buffer[4096];
      ssize_t n = 0;
      message.clear();
      while ((n = ::read(channel[0], buffer, sizeof(buffer))) > 0)
        message.append(buffer, static_cast<std::size_t>(n));
      ::close(channel[0]);
      message    = message.substr(0, message.find('\n'));
      int status = 0;
      ::waitpid(child, &status, 0);
      if (WIFSIGNALED(status))
      {
        message = std::string("signal ") + strsignal(WTERMSIG(status));
        return Outcome::crash;
      }
      switch (WEXITSTATUS(status))
      {
        case 0:
          return Outcome::completed;
        case 1:
          return Outcome::invariant_violation;
        case 2:
          return Outcome::blow_up;
        default:
          return Outcome::other_error;
      }
    }

    /// The names of the outcomes on the command line, indexed by Outcome.
    const std::vector<std::string> outcome_names =
      {"completed", "invariants", "blow-ups", "errors", "crashes", "resumes"};


    /// The contents of @p file ("" if it cannot be read).
    std::string
    contents_of(const std::filesystem::path &file)
    {
      std::ifstream in(file, std::ios::binary);
      return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    }

    /**
     * The episode @p file ran to its end into `output/`: runs it again into
     * `output-resumed/`, with a checkpoint every few steps, stopped at a random step
     * and resumed, and compares the statistics and every VTU file of both, byte for
     * byte. Returns `completed` if they are identical.
     */
    Outcome
    check_resume(const std::string &file, std::mt19937_64 &random, std::string &message)
    {
      namespace fs       = std::filesystem;
      const auto n_lines = [](const std::string &text)
      { return static_cast<unsigned int>(std::count(text.begin(), text.end(), '\n')); };
      const std::string statistics = contents_of("output/statistics.csv");
      // The header, step 0, then one row per step.
      const unsigned int n_steps =
        n_lines(statistics) - std::min(2u, n_lines(statistics));
      if (n_steps < 2)
        return Outcome::completed;
      const auto pick = [&](const unsigned int lo, const unsigned int hi)
      { return std::uniform_int_distribution<unsigned int>(lo, hi)(random); };
      const unsigned int stop  = pick(1, n_steps - 1);
      const unsigned int every = pick(1, stop);
      fs::remove_all("output-resumed");
      for (const bool resume : {false, true})
      {
        const std::string  run = file + (resume ? ".resume.prm" : ".stop.prm");
        std::ostringstream prm;
        prm << "include " << file << "\nset Output directory = output-resumed\n"
            << "subsection Checkpoint\n  set Steps between checkpoints = " << every
            << "\n  set " << (resume ? "Resume = true" : "Stop after steps = ")
            << (resume ? "" : std::to_string(stop)) << "\nend\n";
        write_file_atomically(run, prm.str());
        const Outcome outcome = run_episode(run, run + ".log", message);
        if (outcome != Outcome::completed)
        {
          message = (resume ? "resumed after step " : "stopped after step ")
                    + std::to_string(stop) + ": " + message;
          return Outcome::resume_mismatch;
        }
        fs::remove(run);
        fs::remove(run + ".log");
      }
      std::vector<std::string> files = {"statistics.csv", "solution.pvd"};
      for (const auto &entry : fs::directory_iterator("output"))
        if (entry.path().extension() == ".vtu")
          files.push_back(entry.path().filename().string());
      for (const std::string &name : files)
        if (contents_of(fs::path("output") / name)
            != contents_of(fs::path("output-resumed") / name))
        {
          message = "stopped after step " + std::to_string(stop) + " (checkpoints every "
                    + std::to_string(every) + " steps) and resumed: " + name
                    + " differs from the uninterrupted run's";
          return Outcome::resume_mismatch;
        }
      return Outcome::completed;
    }


    /// The soak in one mode; returns the number of episodes whose outcome fails it.
    unsigned int
    soak(const SoakOptions &options, const bool lod)
    {
      const std::string           mode = lod ? "with-lod" : "without-lod";
      const std::filesystem::path directory =
        std::filesystem::absolute(options.directory) / mode;
      std::filesystem::create_directories(directory);
      std::mt19937_64 random(options.seed + (lod ? 1000003 : 0));
      // The stops of --resume-check draw from their own generator: the episodes are
      // those of the same seed without it.
      std::mt19937_64 resume_random(options.seed + (lod ? 2000003 : 1000));

      const unsigned int n_episodes =
        (options.strokes + options.strokes_per_episode - 1) / options.strokes_per_episode;
      unsigned int strokes = 0, complete = 0, failed = 0;
      unsigned int counts[6] = {0, 0, 0, 0, 0, 0};
      const auto   start     = Clock::now();
      for (unsigned int e = 0; e < n_episodes; ++e)
      {
        const unsigned int n =
          std::min(options.strokes_per_episode, options.strokes - strokes);
        const std::string file =
          (directory / ("episode-" + std::to_string(e) + ".prm")).string();
        write_file_atomically(
          file,
          episode_parameters(
            random, n, lod, options.settings, options.resume_check, complete));
        strokes += n;
        std::string message;
        if (options.resume_check)
          std::filesystem::remove_all("output"); // compared file by file afterwards
        Outcome outcome =
          run_episode(file, (directory / "last-episode.log").string(), message);
        if (outcome == Outcome::completed && options.resume_check)
          outcome = check_resume(file, resume_random, message);
        ++counts[static_cast<int>(outcome)];
        failed += options.fails[static_cast<int>(outcome)];
        if (outcome == Outcome::completed)
          std::filesystem::remove(file);
        else
          std::printf("  episode %u (%s): %s\n", e, file.c_str(), message.c_str());
      }
      const double seconds = Seconds(Clock::now() - start).count();

      std::printf("Soak %s: %u strokes (%u complete, %u partial) in %u episodes of up "
                  "to %u on the pulled slab of square_tear.prm, tears on, invariants "
                  "checked after every step; failed episodes are kept in %s\n",
                  lod ? "on the multiresolution model" : "at full resolution",
                  strokes,
                  complete,
                  strokes - complete,
                  n_episodes,
                  options.strokes_per_episode,
                  directory.c_str());
      print_figure(mode + " strokes", strokes, "");
      // Indexed by Outcome, after `completed`.
      const char *failures[] = {"invariant violations",
                                "blow-ups",
                                "other errors",
                                "crashes",
                                "resume mismatches"};
      for (unsigned int k = 0; k < (options.resume_check ? 5 : 4); ++k)
        print_figure(mode + " " + failures[k], counts[k + 1], "episodes");
      print_figure(mode + " wall time", seconds, "s");
      return failed;
    }

    int
    bench_soak(const std::vector<std::string> &arguments)
    try
    {
      SoakOptions options;
      for (std::size_t i = 0; i < arguments.size(); ++i)
      {
        const std::string &key   = arguments[i];
        const bool         value = i + 1 < arguments.size();
        if (key == "--strokes" && value)
          options.strokes = std::stoul(arguments[++i]);
        else if (key == "--strokes-per-episode" && value)
          options.strokes_per_episode = std::max(1ul, std::stoul(arguments[++i]));
        else if (key == "--seed" && value)
          options.seed = std::stoul(arguments[++i]);
        else if (key == "--fail-on" && value)
        {
          std::fill(options.fails.begin(), options.fails.end(), false);
          for (const std::string &name :
               dealii::Utilities::split_string_list(arguments[++i], ','))
          {
            const auto found =
              std::find(outcome_names.begin() + 1, outcome_names.end(), name);
            if (found == outcome_names.end())
              throw_error("soak: --fail-on takes invariants, blow-ups, errors, "
                          "crashes and resumes, not '",
                          name,
                          "'.");
            options.fails[found - outcome_names.begin()] = true;
          }
        }
        else if (key == "--resume-check")
          options.resume_check = true;
        else if (key == "--set" && value)
          options.settings.push_back(arguments[++i]);
        else if (key == "--directory" && value)
          options.directory = arguments[++i];
        else if (key == "--multiresolution" && value)
        {
          const std::string which = arguments[++i];
          options.without_lod     = which == "off" || which == "both";
          options.with_lod        = which == "on" || which == "both";
          if (!options.without_lod && !options.with_lod)
            throw_error("soak: --multiresolution is off, on or both, not '", which, "'.");
        }
        else
        {
          std::fprintf(stderr,
                       "Usage: lacerta-bench soak [--strokes N (10000)] "
                       "[--strokes-per-episode K (5)] [--multiresolution off|on|both] "
                       "[--seed S (1)] [--directory D (soak)] "
                       "[--set 'Subsection/Entry=value' ...] "
                       "[--resume-check] "
                       "[--fail-on invariants,blow-ups,errors,crashes,resumes (all)]\n");
          return 2;
        }
      }
      unsigned int failed = 0;
      if (options.without_lod)
        failed += soak(options, false);
      if (options.with_lod)
        failed += soak(options, true);
      return failed == 0 ? 0 : 1;
    }
    catch (const std::exception &e)
    {
      std::fprintf(stderr, "soak: %s\n", e.what());
      return 2;
    }
  } // namespace

  LACERTA_REGISTER_BENCHMARK(
    "soak",
    "random scalpel strokes (10^4 by default), complete and partial, some crossing "
    "earlier cuts, on the pulled slab with tears, invariants checked after every "
    "step, at full resolution and on the multiresolution model; prints strokes, "
    "invariant violations, blow-ups, other errors, crashes and wall time, and exits "
    "with 1 if any episode failed (--fail-on chooses which failures count)",
    bench_soak);
} // namespace lacerta::bench
