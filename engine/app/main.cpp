// The command-line program.
//
//   asperity run SCRIPT.lua [key=value ...]   run a script; key=value pairs reach it as `params`
//   asperity run SCRIPT.lua --help            the script's parameters (it receives help=true)
//   asperity repl [SCRIPT.lua] [key=value ...] interactive Lua with the API (after the script)
//   asperity --version                        version, build type, SIMD architecture
//
// Exit status: 0 on success; 1 when the script fails (message "file:line: ..." and a traceback
// on stderr); 2 for a bad command line; 130 when Ctrl-C ended the script.
#include <cctype>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>
#include <vector>
#if defined(__GLIBC__)
#include <malloc.h>  // mallopt
#endif

#include "lua/session.hpp"

namespace {

const char* const kUsage =
    "usage:\n"
    "  asperity run SCRIPT.lua [key=value ...]    run a script (params.key = value)\n"
    "  asperity run SCRIPT.lua --help             the script's parameters (as help=true)\n"
    "  asperity repl [SCRIPT.lua] [key=value ...] interactive session, after SCRIPT if given\n"
    "  asperity --version                         version, build type and SIMD in use\n"
    "  asperity --help                            this text\n";

int usage_error(const std::string& message) {
  std::fprintf(stderr, "asperity: %s\n%s", message.c_str(), kUsage);
  return 2;
}

bool is_identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

// key=value pairs after the script name. --help (or -h) there is help=true: the scripts that
// declare their parameters (scripts/lib/params.lua) then list them instead of running.
bool parse_params(int argc, char** argv, int first, std::vector<std::pair<std::string, std::string>>& out,
                  std::string& error) {
  for (int i = first; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      out.emplace_back("help", "true");
      continue;
    }
    auto eq = a.find('=');
    if (eq == std::string::npos || !is_identifier(a.substr(0, eq))) {
      error = "parameter '" + a + "' is not of the form key=value (key a Lua name)";
      return false;
    }
    out.emplace_back(a.substr(0, eq), a.substr(eq + 1));
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  using asperity::lua::Session;
  if (argc < 2) return usage_error("no command given");
  // Past a file-size limit (ulimit -f) a write should fail with EFBIG, which the writers report
  // as an error naming the file; the default action of SIGXFSZ would kill the run instead.
  std::signal(SIGXFSZ, SIG_IGN);
#if defined(__GLIBC__)
  // Blocks of 128 kB and more are mapped on their own, and the threshold stays there. glibc starts
  // at 128 kB but raises it to the size of each mapped block freed (up to 32 MB), after which the
  // arrays of 128-256 kB that each neighbour build allocates anew come from the heap (the engine
  // maps its own from 256 kB, core/aligned.hpp), and the holes they leave, each build a little
  // larger as a genesis grows its radii, are not reused: a 2 cm genesis then held 142 MB at its
  // peak instead of 62 (of which 20 is the program and Lua).
  mallopt(M_MMAP_THRESHOLD, 128 << 10);
#endif
  std::string command = argv[1];
  try {
    if (command == "--version" || command == "-v" || command == "version") {
      std::printf("%s", asperity::lua::version_text().c_str());
      return 0;
    }
    if (command == "--help" || command == "-h" || command == "help") {
      std::printf("%s", kUsage);
      return 0;
    }
    if (command == "run") {
      if (argc < 3) return usage_error("run: which script? (asperity run SCRIPT.lua)");
      std::string script = argv[2];
      std::vector<std::pair<std::string, std::string>> params;
      std::string error;
      if (!parse_params(argc, argv, 3, params, error)) return usage_error(error);
      Session session;
      session.set_params(script, params);
      if (!session.run_file(script, &error)) {
        std::fprintf(stderr, "%s\n", error.c_str());
        return session.interrupted() ? 130 : 1;
      }
      return 0;
    }
    if (command == "repl") {
      std::string script;
      int first = 2;
      if (argc > 2 && std::strchr(argv[2], '=') == nullptr) {
        script = argv[2];
        first = 3;
      }
      std::vector<std::pair<std::string, std::string>> params;
      std::string error;
      if (!parse_params(argc, argv, first, params, error)) return usage_error(error);
      Session session;
      session.set_params(script, params);
      if (!script.empty() && !session.run_file(script, &error))
        std::fprintf(stderr, "%s\n(the session goes on with what the script did before the error)\n",
                     error.c_str());
      return asperity::lua::repl(session);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "asperity: %s\n", e.what());
    return 1;
  }
  return usage_error("unknown command '" + command + "'");
}
