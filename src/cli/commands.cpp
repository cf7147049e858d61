// The table of subcommands: add a command by writing NAME_command.cpp with a register_NAME()
// function (declared in command.hpp) and listing it here.
#include <array>

#include "command.hpp"

namespace halfback::cli {

namespace {
constexpr std::array<RegisterCommand, 17> kCommands{
    &register_convert,     &register_info,        &register_eval,   &register_resample,
    &register_export_merl, &register_export_rgl,  &register_models, &register_render,
    &register_figure,      &register_study,       &register_view,   &register_fit,
    &register_plan,        &register_reconstruct, &register_factor, &register_nbrdf,
    &register_compare,
};
}  // namespace

std::span<const RegisterCommand> command_table() {
  return kCommands;
}

}  // namespace halfback::cli
