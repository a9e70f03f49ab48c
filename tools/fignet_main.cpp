// `fignet`: the command-line front end. Library errors become one line on stderr and exit code 1;
// usage errors are reported by CLI11 with exit code 2 or more.
#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <cstdio>
#include <exception>

#include "commands.h"
#include "fignet/error.h"

#ifndef FIGNET_VERSION
#define FIGNET_VERSION "unknown"
#endif

namespace {

void add_info_command(CLI::App& app) {
  auto* info = app.add_subcommand("info", "Print the version and how this build was compiled");
  info->callback([] {
    std::printf("fignet %s\n", FIGNET_VERSION);
    std::printf("Eigen %d.%d.%d, SIMD: %s\n", EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION,
                EIGEN_MINOR_VERSION, Eigen::SimdInstructionSetsInUse());
#ifdef __AVX2__
    std::printf("target: x86-64-v3 (AVX2/FMA)\n");
#else
    std::printf("target: portable\n");
#endif
  });
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "FIGNet: learned rigid-body simulation (Face Interaction Graph Networks) for Bullet"};
  app.require_subcommand(1);
  app.set_version_flag("--version", FIGNET_VERSION);
  add_info_command(app);
  fignet::cli::add_graph_stats_command(app);
  fignet::cli::add_generate_command(app);
  fignet::cli::add_train_command(app);
  fignet::cli::add_eval_command(app);
  fignet::cli::add_compare_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const fignet::Error& e) {
    std::fprintf(stderr, "fignet: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fignet: unexpected error: %s\n", e.what());
    return 1;
  }
  return 0;
}
