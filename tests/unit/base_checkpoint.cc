// Checkpoints: the archive reads back what it wrote; a checkpoint file is written so
// that a killed writer leaves a complete one, and a truncated, corrupted or foreign
// file is refused with a message that says which.

#include <lacerta/base/archive.h>
#include <lacerta/base/checkpoint_file.h>
#include <lacerta/base/exceptions.h>

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>
#include <unordered_map>
#include <vector>

namespace
{
  namespace fs = std::filesystem;

  struct Part
  {
    std::vector<double>                                     values;
    std::vector<std::vector<unsigned int>>                  lists;
    std::string                                             name;
    std::optional<std::array<int, 2>>                       pair;
    std::unordered_map<std::uint64_t, std::pair<int, char>> table;

    void
    serialize(lacerta::Archive &archive)
    {
      archive(values, lists, name, pair, table);
    }
  };


  std::string
  error_of(const std::function<void()> &action)
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


  class CheckpointTest : public ::testing::Test
  {
  protected:
    void
    SetUp() override
    {
      directory = fs::temp_directory_path()
                  / ("lacerta-checkpoint-" + std::to_string(::getpid()) + "-"
                     + ::testing::UnitTest::GetInstance()->current_test_info()->name());
      fs::remove_all(directory);
      fs::create_directories(directory);
      file = (directory / "checkpoint.lcp").string();
    }

    void
    TearDown() override
    {
      fs::remove_all(directory);
    }

    fs::path    directory;
    std::string file;
  };
} // namespace


TEST(Archive, ReadsBackWhatItWrote)
{
  Part        written{{1.5, -2, 1e300},
               {{1, 2}, {}, {7}},
               "slab",
               std::array<int, 2>{{3, 4}},
               {{5, {6, 'x'}}, {1ULL << 40, {-1, 'y'}}}};
  std::string bytes;
  {
    lacerta::Archive archive(bytes);
    archive.section("part");
    archive &written;
  }
  Part             read;
  lacerta::Archive archive(bytes, "memory");
  archive.section("part");
  archive &read;
  archive.finish();
  EXPECT_EQ(read.values, written.values);
  EXPECT_EQ(read.lists, written.lists);
  EXPECT_EQ(read.name, written.name);
  EXPECT_EQ(read.pair, written.pair);
  EXPECT_EQ(read.table, written.table);
}


TEST(Archive, RefusesWhatItCannotRead)
{
  std::string bytes;
  {
    lacerta::Archive archive(bytes);
    archive.section("mesh");
    std::vector<double> v(100, 1.0);
    archive            &v;
  }
  // Another part where the mesh was expected.
  EXPECT_NE(error_of(
              [&]
              {
                lacerta::Archive archive(bytes, "x.lcp");
                archive.section("particles");
              })
              .find("holds the part 'mesh' where 'particles' was expected"),
            std::string::npos);
  // Cut short: the size announces more than is left.
  const std::string short_bytes = bytes.substr(0, bytes.size() - 8);
  EXPECT_NE(error_of(
              [&]
              {
                lacerta::Archive    archive(short_bytes, "x.lcp");
                std::vector<double> v;
                archive.section("mesh");
                archive &v;
              })
              .find("x.lcp"),
            std::string::npos);
  // Bytes left over: the state of another scene.
  EXPECT_NE(error_of(
              [&]
              {
                lacerta::Archive archive(bytes, "x.lcp");
                archive.section("mesh");
                archive.finish();
              })
              .find("bytes after the state"),
            std::string::npos);
}


TEST_F(CheckpointTest, KeepsThePreviousCheckpoint)
{
  lacerta::write_checkpoint_file(file, "first");
  EXPECT_FALSE(fs::exists(file + ".previous"));
  lacerta::write_checkpoint_file(file, "second");
  EXPECT_EQ(lacerta::read_checkpoint_file(file), "second");
  EXPECT_EQ(lacerta::read_checkpoint_file(file + ".previous"), "first");
  lacerta::write_checkpoint_file(file, "third");
  EXPECT_EQ(lacerta::read_checkpoint_file(file), "third");
  EXPECT_EQ(lacerta::read_checkpoint_file(file + ".previous"), "second");
}


TEST_F(CheckpointTest, RefusesDamagedAndForeignFiles)
{
  const std::string payload(10000, 'a');
  lacerta::write_checkpoint_file(file, payload);
  std::string whole;
  {
    std::ifstream in(file, std::ios::binary);
    whole.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const auto write = [&](const std::string &contents)
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out << contents;
  };
  const auto message = [&]
  { return error_of([&] { lacerta::read_checkpoint_file(file); }); };

  write(whole.substr(0, whole.size() - 1));
  EXPECT_NE(message().find("is truncated"), std::string::npos) << message();
  write(whole.substr(0, 20));
  EXPECT_NE(message().find("is truncated"), std::string::npos) << message();
  std::string corrupted = whole;
  corrupted[whole.size() / 2] ^= 1;
  write(corrupted);
  EXPECT_NE(message().find("is corrupted"), std::string::npos) << message();
  std::string other_version = whole;
  other_version[19]         = 99;
  write(other_version);
  EXPECT_NE(message().find("has format version 99"), std::string::npos) << message();
  write("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\">\n");
  EXPECT_NE(message().find("is not a Lacerta checkpoint"), std::string::npos)
    << message();
  fs::remove(file);
  EXPECT_NE(message().find("cannot read"), std::string::npos) << message();
}


// A writer killed at random moments, while it writes checkpoints one after another,
// always leaves a complete checkpoint: the last one written or the one being replaced.
TEST_F(CheckpointTest, KilledWriterLeavesACompleteCheckpoint)
{
  // Large enough that a kill often lands inside a write.
  const auto payload_of = [](const unsigned int i)
  { return std::string(4u << 20, static_cast<char>('a' + i % 26)); };
  lacerta::write_checkpoint_file(file, payload_of(0));
  std::mt19937 random(42);
  unsigned int kills_during_a_write = 0;
  for (unsigned int round = 0; round < 20; ++round)
  {
    // The last kill's temporary file goes, so that its reappearance shows that the
    // new writer has started (which takes long under the sanitizers or on a loaded
    // machine); the kill then comes at a random moment of the next 20 ms.
    fs::remove(file + ".tmp");
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0)
    {
      for (unsigned int i = 1;; ++i)
        lacerta::write_checkpoint_file(file, payload_of(i));
    }
    for (unsigned int wait = 0; wait < 20000 && !fs::exists(file + ".tmp"); ++wait)
      std::this_thread::sleep_for(std::chrono::microseconds(100));
    std::this_thread::sleep_for(
      std::chrono::microseconds(std::uniform_int_distribution<int>(0, 20000)(random)));
    ::kill(child, SIGKILL);
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status));
    kills_during_a_write += fs::exists(file + ".tmp") ? 1 : 0;
    // The checkpoint is whole: one of the payloads, all of it.
    const std::string payload = lacerta::read_checkpoint_file(file);
    ASSERT_EQ(payload.size(), 4u << 20);
    EXPECT_EQ(payload, std::string(payload.size(), payload[0]));
    if (fs::exists(file + ".previous"))
    {
      EXPECT_EQ(lacerta::read_checkpoint_file(file + ".previous").size(), 4u << 20);
    }
  }
  // The test means something only if some kills came in the middle of a write.
  EXPECT_GT(kills_during_a_write, 0u);
}
