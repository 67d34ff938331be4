// msm: the command-line front end of the moment shadow mapping toolkit.
#include "commands.h"
#include "usage.h"

#include "msm/util/limits.h"

#include <fmt/core.h>

#include <cstdio>
#include <exception>
#include <string>

namespace {

// CLI11 reports an option of one value given twice as "--width: At Most 1 required but received 3"
// (counting its values and separators): said plainly, naming the option.
CLI::ArgumentMismatch plain_argument_mismatch(const CLI::ArgumentMismatch& error) {
  const std::string what = error.what();
  const std::string at_most = ": At Most 1 required but received ";
  const std::size_t at = what.find(at_most);
  if (at == std::string::npos) return error;
  return CLI::ArgumentMismatch(fmt::format("{} given more than once: it takes one value", what.substr(0, at)));
}

} // namespace

int main(int argc, char** argv) {
  CLI::App app;
  msm::tool::build_app(app);
  try {
    msm::limits::check_environment(); // a mistyped override is refused before any work
    app.parse(argc, argv);
  } catch (const CLI::ArgumentMismatch& e) {
    return msm::tool::report_parse_error(app, plain_argument_mismatch(e));
  } catch (const CLI::ParseError& e) { return msm::tool::report_parse_error(app, e); } catch (const std::exception& e) {
    fmt::print(stderr, "msm: error: {}\n", e.what());
    return msm::tool::kExitFailure;
  }
  return 0;
}
