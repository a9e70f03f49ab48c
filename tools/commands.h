// Each subcommand of the `fignet` tool registers itself on the top-level app.
#pragma once

#include <CLI/CLI.hpp>

namespace fignet::cli {

void add_graph_stats_command(CLI::App& app);
void add_generate_command(CLI::App& app);
void add_train_command(CLI::App& app);
void add_eval_command(CLI::App& app);
void add_compare_command(CLI::App& app);
void add_stress_command(CLI::App& app);

}  // namespace fignet::cli
