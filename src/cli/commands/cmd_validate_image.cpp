// `hprt validate image A B [--json] [--diff D.png] [--min-psnr DB]
// [--threshold T] [--max-pixels-over N]`: compares two images (validators/
// image_diff); exit 1 when PSNR < min-psnr or more than N pixels differ by
// more than T in some channel, exit 2 when the images cannot be compared.
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "io/image/image_io.h"
#include "validators/image_diff.h"

namespace hprt::cli {
namespace {

struct ValidateImageArgs {
  std::string a, b;
  std::string diff;
  double min_psnr = 40.0;
  double threshold = kDefaultDiffThreshold;
  uint64_t max_pixels_over = 0;
  bool json = false;
};

int run_validate_image(const ValidateImageArgs& args) {
  if (!args.diff.empty()) check_image_output(args.diff);
  const Image a = read_image(args.a);
  const Image b = read_image(args.b);
  const ImageDiff d = diff_images(a, b, args.threshold, args.a, args.b);
  if (!args.diff.empty()) write_diff_heatmap(args.diff, a, b);
  const bool pass = d.psnr_db >= args.min_psnr && d.pixels_over <= args.max_pixels_over;

  std::fprintf(stderr,
               "hprt validate image: %dx%d, PSNR %.2f dB (min %.2f), RMSE %.6g, max error %.6g "
               "at (%d, %d), %llu of %llu pixels over %.4g (max %llu): %s\n",
               d.width, d.height, d.psnr_db, args.min_psnr, d.rmse, d.max_error, d.max_x, d.max_y,
               (unsigned long long)d.pixels_over, (unsigned long long)d.pixels, args.threshold,
               (unsigned long long)args.max_pixels_over, pass ? "pass" : "FAIL");
  if (args.json) {
    nlohmann::json j;
    // JSON has no infinity: identical images report psnr_db null, identical true.
    j["psnr_db"] = std::isfinite(d.psnr_db) ? nlohmann::json(d.psnr_db) : nlohmann::json(nullptr);
    j["identical"] = d.rmse == 0.0;
    j["rmse"] = d.rmse;
    j["mean_error"] = d.mean_error;
    j["max_error"] = d.max_error;
    j["max_error_pixel"] = {d.max_x, d.max_y};
    j["pixels_over"] = d.pixels_over;
    j["pixels"] = d.pixels;
    j["threshold"] = args.threshold;
    j["min_psnr"] = args.min_psnr;
    j["max_pixels_over"] = args.max_pixels_over;
    j["width"] = d.width;
    j["height"] = d.height;
    j["pass"] = pass;
    if (!args.diff.empty()) j["diff"] = args.diff;
    std::cout << j.dump() << std::endl;
  }
  return pass ? 0 : 1;
}

}  // namespace

void add_validate_image_command(CLI::App& validate, CommandState& state) {
  auto args = std::make_shared<ValidateImageArgs>();
  CLI::App* cmd = validate.add_subcommand("image", "compare two images (PSNR, RMSE, max error)");
  cmd->add_option("a", args->a, "first image")->required();
  cmd->add_option("b", args->b, "second image")->required();
  cmd->add_option("--diff", args->diff, "write a heat map of |A - B| (scaled to the max)");
  cmd->add_option("--min-psnr", args->min_psnr, "fail below this PSNR in dB")
      ->capture_default_str();
  cmd->add_option("--threshold", args->threshold,
                  "per-channel |A - B| (values in [0, 1]) above which a pixel counts as over")
      ->check(CLI::Range(0.0, 1e30))
      ->capture_default_str();
  cmd->add_option("--max-pixels-over", args->max_pixels_over,
                  "fail when more pixels than this are over the threshold")
      ->capture_default_str();
  cmd->add_flag("--json", args->json, "print one JSON object on stdout");
  cmd->callback([args, &state] { state.exit_code = run_validate_image(*args); });
}

}  // namespace hprt::cli
