// A Lua session with the asperity API loaded: what `asperity run`, `asperity repl` and the
// tests use. This header is the Lua layer's face to the program (engine/app) and does not
// include lua.h: nothing outside engine/lua/ does.
#pragma once

#include <string>
#include <utility>
#include <vector>

struct lua_State;

namespace asperity::lua {

// Where the project's Lua library lives: $ASPERITY_SCRIPTS_DIR if set, else the scripts/
// directory of the source tree this program was built from.
std::string scripts_dir();

// "asperity 0.1.0 (Release) ..." with the SIMD architecture in use and Lua's version.
std::string version_text();

class Session {
 public:
  Session();
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  lua_State* state() { return L_; }

  // The global table `params` from key=value pairs: numbers converted, true/false booleans,
  // anything else a string. Also the global `arg` (script name at 0, as lua.c does).
  void set_params(const std::string& script, const std::vector<std::pair<std::string, std::string>>& params);

  // Runs a file / a string. On error returns false and sets *error to "file:line: message"
  // followed by a traceback. The SIGINT handler is installed for the duration.
  bool run_file(const std::string& path, std::string* error);
  bool run_string(const std::string& code, const std::string& chunk_name, std::string* error);

  // Whether the last failure was a Ctrl-C (an interruption, interrupt.hpp).
  bool interrupted() const { return interrupted_; }

 private:
  // After a load or call with this status: false, with the error's text in *error, on failure.
  bool finish(int status, std::string* error);
  lua_State* L_;
  bool interrupted_ = false;
};

// The interactive loop (readline when stdin is a terminal; plain lines, no prompts, otherwise).
// Returns the exit status: 0, or 1 when input was not a terminal and some chunk failed.
int repl(Session& session);

}  // namespace asperity::lua
