// Result files: a failed write is an Error naming the file and the reason, and what
// was written before stays valid.

#include <lacerta/base/exceptions.h>
#include <lacerta/base/output_file.h>

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <unistd.h>

namespace
{
  namespace fs = std::filesystem;

  std::string
  contents(const fs::path &file)
  {
    std::ifstream in(file);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }


  // A fresh directory for one test, removed afterwards.
  class OutputFileTest : public ::testing::Test
  {
  protected:
    void
    SetUp() override
    {
      directory = fs::temp_directory_path()
                  / ("lacerta-output-file-" + std::to_string(::getpid()) + "-"
                     + ::testing::UnitTest::GetInstance()->current_test_info()->name());
      fs::remove_all(directory);
      fs::create_directories(directory);
    }

    void
    TearDown() override
    {
      fs::permissions(directory, fs::perms::owner_all);
      fs::remove_all(directory);
    }

    // The message of the Error that @p action throws, or "" if it throws none.
    template <typename Action>
    static std::string
    error_of(const Action &action)
    {
      try
      {
        action();
      }
      catch (const lacerta::Error &e)
      {
        return e.what();
      }
      return "";
    }

    fs::path directory;
  };


  TEST_F(OutputFileTest, AnAtomicWriteReplacesTheFileAndLeavesNoTemporary)
  {
    const std::string file = (directory / "series.pvd").string();
    lacerta::write_file_atomically(file, "first");
    lacerta::write_file_atomically(file, "second", true);
    EXPECT_EQ(contents(file), "second");
    EXPECT_FALSE(fs::exists(file + ".tmp"));
  }


  TEST_F(OutputFileTest, AFullDiskKeepsThePreviousFileAndNamesTheFile)
  {
    const std::string file = (directory / "series.pvd").string();
    lacerta::write_file_atomically(file, "complete");
    // The temporary meets a full disk.
    fs::create_symlink("/dev/full", file + ".tmp");
    const std::string message =
      error_of([&] { lacerta::write_file_atomically(file, "longer contents"); });
    EXPECT_EQ(message, "Cannot write '" + file + "': No space left on device.");
    EXPECT_EQ(contents(file), "complete");
    EXPECT_FALSE(fs::exists(fs::symlink_status(file + ".tmp")));
  }


  TEST_F(OutputFileTest, AMissingDirectoryIsNamed)
  {
    const std::string file = (directory / "missing" / "statistics.csv").string();
    EXPECT_EQ(error_of([&] { lacerta::OutputFile table(file); }),
              "Cannot write '" + file + "': No such file or directory.");
    EXPECT_EQ(error_of([&] { lacerta::write_file_atomically(file, "x"); }),
              "Cannot write '" + file + "': No such file or directory.");
  }


  TEST_F(OutputFileTest, AReadOnlyDirectoryIsNamed)
  {
    if (::geteuid() == 0)
      GTEST_SKIP() << "permissions do not bind the superuser";
    fs::permissions(directory, fs::perms::owner_read | fs::perms::owner_exec);
    const std::string file = (directory / "statistics.csv").string();
    EXPECT_EQ(error_of([&] { lacerta::OutputFile table(file); }),
              "Cannot write '" + file + "': Permission denied.");
  }


  TEST_F(OutputFileTest, RowsAreInTheFileAsSoonAsTheyAreAppended)
  {
    const std::string   file = (directory / "statistics.csv").string();
    lacerta::OutputFile table(file);
    table.append("step,time\n");
    table.append("0,0\n");
    // Not closed yet: a run killed now keeps both rows.
    EXPECT_EQ(contents(file), "step,time\n0,0\n");
    lacerta::OutputFile moved = std::move(table);
    moved.append("1,0.001\n");
    EXPECT_EQ(contents(file), "step,time\n0,0\n1,0.001\n");
    EXPECT_EQ(moved.name(), file);
  }


  TEST_F(OutputFileTest, AnAppendToAFullDiskIsAnError)
  {
    lacerta::OutputFile table("/dev/full");
    EXPECT_EQ(error_of([&] { table.append("step,time\n"); }),
              "Cannot write '/dev/full': No space left on device.");
    lacerta::OutputFile closed;
    EXPECT_NE(error_of([&] { closed.append("x"); }), "");
  }
} // namespace
