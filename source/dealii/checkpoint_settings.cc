#include <mpm/dealii/checkpoint_settings.h>

namespace mpm
{
  using dealii::ParameterHandler;
  namespace Patterns = dealii::Patterns;

  void CheckpointSettings::declare(ParameterHandler &prm)
  {
    prm.declare_entry("Step interval", "0", Patterns::Integer(0),
                      "Steps between checkpoints (the whole state of the run, from which --resume continues it "
                      "exactly); 0 = none by step count.");
    prm.declare_entry("Wall-clock interval", "0", Patterns::Double(0),
                      "Wall-clock minutes between checkpoints; 0 = none by wall-clock time. On several ranks the "
                      "rank whose clock is first due decides for all.");
    prm.declare_entry("Number kept", "2", Patterns::Integer(1),
                      "Newest checkpoints kept in the folder; older ones are deleted once a newer one is complete.");
    prm.declare_entry("Directory", "", Patterns::DirectoryName(),
                      "Folder of the checkpoints (one sub-folder checkpoint-NNNNNNNNN per checkpoint, NNNNNNNNN its "
                      "step); empty = the folder 'checkpoints' in Output/Directory.");
    prm.declare_entry("At end", "false", Patterns::Bool(),
                      "Also write a checkpoint when the run ends, so that it can be continued to a later End time "
                      "(dealii-mpm scene.prm --resume FOLDER with the End time raised).");
  }

  void CheckpointSettings::parse(ParameterHandler &prm, const std::string &output_directory)
  {
    step_interval = prm.get_integer("Step interval");
    wall_interval = prm.get_double("Wall-clock interval");
    keep          = prm.get_integer("Number kept");
    directory     = prm.get("Directory");
    at_end        = prm.get_bool("At end");
    if (directory.empty())
      directory = (output_directory.empty() ? std::string(".") : output_directory) + "/checkpoints";
  }
} // namespace mpm
