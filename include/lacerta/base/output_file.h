/**
 * @file
 * Writing result files so that a failed write ends the run with a clear message and
 * never leaves a result file half written.
 */
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace lacerta
{
  class Archive;

  /**
   * Creates @p directory and its parents if they do not exist; an Error names the
   * directory (as `Output directory`) and the system's reason if that fails.
   */
  void
  create_output_directory(const std::string &directory);

  /**
   * Replaces @p file_name by @p contents atomically: the contents go to a temporary file
   * beside it, which is renamed over @p file_name once complete, so a reader, a full disk
   * or a killed process never sees it half written. With @p to_disk the contents are also
   * flushed to the disk (fsync) before the rename, so that they survive a power loss
   * too; results leave it off, checkpoints need it. If anything fails (a read-only
   * directory, a full disk), the temporary is removed, the previous @p file_name is left
   * as it was, and an Error names the file and the system's reason.
   */
  void
  write_file_atomically(const std::string &file_name,
                        std::string_view   contents,
                        bool               to_disk = false);

  /**
   * A result file written piece by piece, such as a table with one row per step. Every
   * append is handed to the operating system at once, so the rows written before the
   * run ends (normally, by an error or by a kill) stay in the file; a write that fails
   * throws an Error that names the file and the system's reason.
   */
  class OutputFile
  {
  public:
    /**
     * A file that is not open yet.
     */
    OutputFile() = default;

    /**
     * Creates @p file_name, or empties it if it exists.
     */
    explicit OutputFile(const std::string &file_name);

    OutputFile(const OutputFile &) = delete;
    OutputFile &
    operator=(const OutputFile &) = delete;

    /**
     * Takes over the file of @p other.
     */
    OutputFile(OutputFile &&other) noexcept;

    /**
     * Closes the file it holds and takes over the file of @p other.
     */
    OutputFile &
    operator=(OutputFile &&other) noexcept;

    /**
     * Closes the file.
     */
    ~OutputFile();

    /**
     * Writes @p text at the end of the file.
     */
    void
    append(std::string_view text);

    /**
     * The file's name.
     */
    const std::string &
    name() const;

    /**
     * Writes the file's contents so far into a checkpoint, or, when @p archive loads,
     * replaces what the file holds by the contents the checkpoint kept, so that the
     * rows written after the checkpoint are gone and the next append follows the
     * last row it kept.
     */
    void
    serialize(Archive &archive);

  private:
    std::string file_name;
    int         descriptor = -1;
    /// Bytes appended since the file was created.
    std::size_t written = 0;
  };
} // namespace lacerta
