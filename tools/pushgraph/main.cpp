// pushgraph: command-line front end. Each subcommand is a thin layer over the libraries.
#include "cli_common.h"

#include <cstdio>
#include <exception>
#include <iostream>

#ifdef PUSHGRAPH_WITH_GRAPH
#include <glog/logging.h>
#endif

int main(int argc, char** argv) {
  using namespace pushgraph::cli;
#ifdef PUSHGRAPH_WITH_GRAPH
  // Ceres logs through glog: to stderr, no log files, and no "Logging before
  // InitGoogleLogging()" line ahead of the first one.
  FLAGS_logtostderr = true;
  // Errors only: a warning of Ceres (a rank-deficient covariance) is already in the result's
  // covariance status, and a raw log line on stderr read as a crash to a user.
  FLAGS_minloglevel = google::GLOG_ERROR;
  google::InitGoogleLogging(argv[0]);
#endif
  CLI::App app{"pushgraph: geometry-exact planar contact, limit surfaces and pushing estimation"};
  app.require_subcommand(1, 1);
  app.set_version_flag("--version", "pushgraph 0.1.0");
  RegisterDistance(app);
  RegisterPenetration(app);
  RegisterLimitSurface(app);
  RegisterSimulate(app);
  RegisterDemo(app);
#ifdef PUSHGRAPH_WITH_GRAPH
  RegisterEstimate(app);
  RegisterEvaluate(app);
#endif
  RegisterFootprint(app);
  RegisterMitImport(app);

  std::vector<std::string> args(argv + 1, argv + argc);
  // A first word that is no subcommand is named (CLI11 would only say that one is required).
  if (!args.empty() && !args[0].empty() && args[0][0] != '-') {
    std::string names;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands({})) {
      known = known || sub->check_name(args[0]);
      names += (names.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      std::cerr << "pushgraph: unknown subcommand '" << args[0] << "'; the subcommands are " << names
                << " (see pushgraph --help)\n";
      return 2;
    }
  }
  // Every option that takes a value may be given a negative number after a space.
  std::vector<std::string> value_options;
  for (const CLI::App* sub : app.get_subcommands({})) {
    for (const CLI::Option* opt : sub->get_options()) {
      if (opt->get_type_size() == 0) continue;  // flags
      for (const std::string& name : opt->get_lnames()) value_options.push_back("--" + name);
    }
  }
  args = JoinNegativeValues(args, value_options);
  // No option or argument of this tool means anything empty: `-o ""` ran a whole estimate and then
  // failed to write "" (an empty path reads as "not given" to the output checks).
  for (CLI::App* sub : app.get_subcommands({})) {
    for (CLI::Option* opt : sub->get_options()) {
      if (opt->get_type_size() == 0) continue;
      opt->check(CLI::Validator(
          [](std::string& value) { return value.empty() ? std::string("an empty value") : std::string(); },
          "", "NonEmpty"));
    }
  }
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    app.parse(reversed);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "pushgraph: " << WithGivenInputPaths(e.what()) << " (see pushgraph --help)\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "pushgraph: error: " << WithGivenInputPaths(e.what()) << "\n";
    return 1;
  }
  return 0;
}
