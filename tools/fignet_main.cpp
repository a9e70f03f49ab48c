// `fignet`: the command-line front end. Library errors become one line on stderr and exit code 1;
// usage errors are reported by CLI11 with exit code 2 or more.
#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>

#include "commands.h"
#include "fignet/error.h"
#include "fignet/nn/gemm.h"
#include "process_group.h"
#ifdef FIGNET_WITH_MPI
#include "fignet/parallel/mpi_collective.h"
#endif

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
    std::printf("matrix products: %s\n", fignet::gemm_description().c_str());
    const std::string bf16 = fignet::gemm_precision_unavailable(fignet::GemmPrecision::kBf16);
    std::printf("bf16 products (--bf16): %s\n",
                bf16.empty() ? "available" : ("not here: " + bf16).c_str());
  });
}

}  // namespace

namespace fignet::cli {
ProcessGroup& process_group() {
  static ProcessGroup group;
  return group;
}
}  // namespace fignet::cli

int main(int argc, char** argv) {
  // Under mpirun every process runs this program; alone it is one process and MPI stays idle.
  fignet::Collective one_process;
  fignet::cli::process_group().collective = &one_process;
#ifdef FIGNET_WITH_MPI
  fignet::MpiSession mpi(&argc, &argv);
  std::unique_ptr<fignet::MpiCollective> processes;
  if (mpi.active()) {
    processes = std::make_unique<fignet::MpiCollective>();
    fignet::cli::process_group().collective = processes.get();
  }
  // One process failing would leave the others waiting in a collective: end them all.
  const auto fail = [&](int code) {
    if (fignet::cli::process_group().size() > 1) mpi.abort(code);
    return code;
  };
#else
  const auto fail = [](int code) { return code; };
#endif
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
  fignet::cli::add_stress_command(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const fignet::Error& e) {
    std::fprintf(stderr, "fignet: error: %s\n", e.what());
    return fail(1);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fignet: unexpected error: %s\n", e.what());
    return fail(1);
  }
  return 0;
}
