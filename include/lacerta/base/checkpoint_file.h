/**
 * @file
 * The checkpoint file: a state written so that a kill, a full disk or a power loss
 * never leaves a run without a checkpoint to resume from, and read back only if it is
 * whole.
 */
#pragma once

#include <string>
#include <string_view>

namespace lacerta
{
  /**
   * Writes @p payload (an Archive's contents) as the checkpoint @p file_name: a header
   * (the format's name and version, the payload's length and checksum), then the
   * payload, to a temporary file flushed to the disk and renamed over @p file_name.
   * The checkpoint it replaces stays as `<file_name>.previous`, so that at every
   * moment @p file_name is a complete checkpoint (the old or the new) and the one
   * before it is kept. An Error names the file and the system's reason if a write
   * fails; the checkpoints already written are then left as they were.
   */
  void
  write_checkpoint_file(const std::string &file_name, std::string_view payload);

  /**
   * Reads the checkpoint @p file_name and returns its payload. A missing file, a file
   * that is not a Lacerta checkpoint, one of another format version, or one whose
   * length or checksum does not match (truncated, corrupted) is an Error that names
   * the file and says which.
   */
  std::string
  read_checkpoint_file(const std::string &file_name);
} // namespace lacerta
