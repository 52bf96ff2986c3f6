// `hprt validate`: the parent of `validate rays` (bvh vs embree with the exact
// arbiter), `validate query` (count, inside and closest, with exact judges)
// and `validate image` (image comparison).
#include "cli/commands.h"

namespace hprt::cli {

void add_validate_command(CLI::App& app, CommandState& state) {
  CLI::App* validate = app.add_subcommand("validate", "check hprt against Embree or images");
  validate->require_subcommand(1);
  add_validate_rays_command(*validate, state);
  add_validate_query_command(*validate, state);
  add_validate_image_command(*validate, state);
}

}  // namespace hprt::cli
