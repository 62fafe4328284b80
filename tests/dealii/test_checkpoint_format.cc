// Checkpoint files of another format are refused by name: a run.state of format 1 (before the
// strength divisor, 2026-12-03) or 2 (before the named point fields, 2026-12-07) says so, and a file of no known format says it is not a checkpoint.
// (That format 3 carries the divisor through: prm/checkpoint/TERM_prefailure_resume.)
#include <mpm/dealii/checkpoint.h>

#include <deal.II/base/exceptions.h>

#include <boost/archive/binary_oarchive.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

namespace
{
  // A run.state holding only the format mark (what is read first).
  void write_mark(const std::string &folder, const unsigned int mark)
  {
    std::filesystem::create_directories(folder);
    std::ofstream                   out(folder + "/run.state", std::ios::binary);
    boost::archive::binary_oarchive archive(out);
    archive << mark;
  }

  // The message of read_state on folder, or "" where it read the state.
  std::string refusal(const std::string &folder)
  {
    try
      {
        mpm::checkpoint::read_state(folder);
      }
    catch (const dealii::ExceptionBase &e)
      {
        // The message alone, its words joined by single spaces (deal.II's what() wraps lines).
        std::ostringstream info;
        e.print_info(info);
        std::istringstream words(info.str());
        std::string        joined, word;
        while (words >> word)
          joined += (joined.empty() ? "" : " ") + word;
        return joined;
      }
    return "";
  }
} // namespace

int main()
{
  const std::string root = std::filesystem::temp_directory_path() / "mpm_test_checkpoint_format";
  std::filesystem::remove_all(root);
  int failures = 0;
  const auto expect = [&failures](const bool ok, const std::string &what) {
    std::cout << (ok ? "ok: " : "FAILED: ") << what << std::endl;
    failures += !ok;
  };

  write_mark(root + "/format1", 0x4d504d01);
  expect(refusal(root + "/format1").find("checkpoint format 1") != std::string::npos,
         "a format-1 run.state is refused as written by an earlier dealii-mpm");
  write_mark(root + "/format2", 0x4d504d02);
  expect(refusal(root + "/format2").find("checkpoint format 2, before 2026-12-07") != std::string::npos,
         "a format-2 run.state (arrays in a fixed order, no field names) is refused as earlier");
  write_mark(root + "/other", 12345);
  expect(refusal(root + "/other").find("is not a dealii-mpm checkpoint file") != std::string::npos,
         "a run.state of no known format is refused as not a checkpoint");

  std::filesystem::remove_all(root);
  return failures == 0 ? 0 : 1;
}
