// The interactive loop, in lua.c's pieces:
// - read: one line, from a terminal through GNU readline or from a pipe as it is;
// - compile: `return <input>` first so that expressions print their value, else the input as a
//   statement; input the parser stopped in at <eof> (incomplete) continues on the next line,
//   with a ">>" prompt. "=x" is x, as in lua.c;
// - run: the chunk with the traceback-adding message handler of session.cpp;
// - print_results: the Lua printer of session.cpp (tables one level deep); report: errors with
//   their traceback, except Ctrl-C interruptions (told by type, interrupt.hpp), which print
//   their message alone.
// With a terminal: readline through its callback interface, driven by select(), because a
// signal then interrupts select() (EINTR) and the loop can act on Ctrl-C itself: clear the line,
// and exit on a second Ctrl-C in a row. History in ~/.asperity_history; tab completion of
// globals, fields and methods (a.b.c, obj:method) read with raw accesses only, so completing can
// never run user code or raise.
// Without a terminal (a pipe, a test): plain lines, no prompts, results on stdout, errors on
// stderr, and the exit status tells whether any chunk failed.
#include <readline/history.h>
#include <readline/readline.h>
#include <sys/select.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <set>
#include <string_view>

#include "lua/binding.hpp"
#include "lua/interrupt.hpp"
#include "lua/session.hpp"

namespace asperity::lua {

int call_with_traceback(lua_State* L, int nargs, int nresults);  // session.cpp

namespace {

lua_State* completion_state = nullptr;

// ---------------------------------------------------------------------------------------------
// Completion

const char* const kKeywords[] = {"and",   "break", "do",  "else", "elseif", "end",
                                 "false", "for",   "function", "goto", "if", "in",
                                 "local", "nil",   "not", "or",   "repeat", "return",
                                 "then",  "true",  "until", "while"};

// Pushes t[key] without metamethods, but looking through a metatable's `methods` / __index
// table the way method lookups of our userdata go. Pushes nil if there is nothing.
void raw_field(lua_State* L, int t, const std::string& key) {
  t = lua_absindex(L, t);
  if (lua_type(L, t) == LUA_TTABLE) {
    lua_pushlstring(L, key.data(), key.size());
    if (lua_rawget(L, t) != LUA_TNIL) return;
    lua_pop(L, 1);
  }
  if (lua_getmetatable(L, t)) {
    for (const char* name : {"methods", "__index"}) {
      lua_pushstring(L, name);
      if (lua_rawget(L, -2) == LUA_TTABLE) {
        lua_pushlstring(L, key.data(), key.size());
        if (lua_rawget(L, -2) != LUA_TNIL) {
          lua_remove(L, -2);
          lua_remove(L, -2);
          return;
        }
        lua_pop(L, 1);
      }
      lua_pop(L, 1);
    }
    lua_pop(L, 1);
  }
  lua_pushnil(L);
}

void collect_keys(lua_State* L, int t, const std::string& partial, bool functions_only,
                  std::set<std::string>& out) {
  t = lua_absindex(L, t);
  auto from_table = [&](int table) {
    lua_pushnil(L);
    while (lua_next(L, table)) {
      if (lua_type(L, -2) == LUA_TSTRING && (!functions_only || lua_type(L, -1) == LUA_TFUNCTION)) {
        std::string k = lua_tostring(L, -2);
        bool identifier = !k.empty() && (std::isalpha(static_cast<unsigned char>(k[0])) || k[0] == '_');
        if (identifier && k.compare(0, partial.size(), partial) == 0 && k.rfind("__", 0) != 0)
          out.insert(k);
      }
      lua_pop(L, 1);
    }
  };
  if (lua_type(L, t) == LUA_TTABLE) from_table(t);
  if (lua_getmetatable(L, t)) {
    for (const char* name : {"methods", "__index"}) {
      lua_pushstring(L, name);
      if (lua_rawget(L, -2) == LUA_TTABLE) from_table(lua_gettop(L));
      lua_pop(L, 1);
    }
    lua_pop(L, 1);
  }
}

std::vector<std::string> candidates(const std::string& text) {
  lua_State* L = completion_state;
  std::vector<std::string> out;
  if (!L || !lua_checkstack(L, 20)) return out;
  int top = lua_gettop(L);
  auto sep = text.find_last_of(".:");
  std::set<std::string> keys;
  if (sep == std::string::npos) {
    lua_pushglobaltable(L);
    collect_keys(L, -1, text, false, keys);
    for (const char* k : kKeywords)
      if (std::string(k).rfind(text, 0) == 0) keys.insert(k);
    out.assign(keys.begin(), keys.end());
  } else {
    // Walk the chain a.b.c before the last separator.
    std::string chain = text.substr(0, sep);
    lua_pushglobaltable(L);
    std::size_t start = 0;
    bool ok = true;
    while (ok && start <= chain.size()) {
      std::size_t end = chain.find_first_of(".:", start);
      std::string part = chain.substr(start, end == std::string::npos ? std::string::npos : end - start);
      raw_field(L, -1, part);
      lua_remove(L, -2);
      ok = !lua_isnil(L, -1);
      if (end == std::string::npos) break;
      start = end + 1;
    }
    if (ok) {
      collect_keys(L, -1, text.substr(sep + 1), text[sep] == ':', keys);
      for (const std::string& k : keys) out.push_back(text.substr(0, sep + 1) + k);
    }
  }
  lua_settop(L, top);
  return out;
}

char* generator(const char* text, int state) {
  static std::vector<std::string> list;
  static std::size_t next;
  if (state == 0) {
    list = candidates(text);
    next = 0;
  }
  if (next < list.size()) return strdup(list[next++].c_str());
  return nullptr;
}

char** complete(const char* text, int, int) {
  rl_attempted_completion_over = 1;  // no file-name completion
  rl_completion_append_character = '\0';  // readline resets it before every completion
  return rl_completion_matches(text, generator);
}

// ---------------------------------------------------------------------------------------------
// Reading lines

enum class Read { line, eof, interrupt };

std::string pending_line;
bool line_ready = false, line_eof = false;

void on_line(char* line) {
  line_ready = true;
  line_eof = line == nullptr;
  pending_line = line ? line : "";
  std::free(line);
  rl_callback_handler_remove();
}

Read read_terminal(const char* prompt, std::string& out) {
  line_ready = false;
  rl_callback_handler_install(prompt, on_line);
  set_at_prompt(true);
  Read result = Read::line;
  while (!line_ready) {
    fd_set fds;
    FD_ZERO(&fds);
    FD_SET(STDIN_FILENO, &fds);
    int r = select(STDIN_FILENO + 1, &fds, nullptr, nullptr, nullptr);
    if (r < 0) {
      if (errno == EINTR && take_prompt_interrupt()) {
        rl_free_line_state();
        rl_callback_sigcleanup();
        rl_replace_line("", 0);
        rl_callback_handler_remove();
        std::fputs("^C\n", stdout);
        result = Read::interrupt;
        break;
      }
      if (errno == EINTR) continue;
      rl_callback_handler_remove();
      result = Read::eof;
      break;
    }
    rl_callback_read_char();
  }
  set_at_prompt(false);
  if (result != Read::line) return result;
  if (line_eof) return Read::eof;
  out = pending_line;
  return Read::line;
}

std::string history_path() {
  const char* home = std::getenv("HOME");
  return std::string(home && *home ? home : ".") + "/.asperity_history";
}

// Where the lines come from: readline with history and completion on a terminal, plain lines
// from a pipe.
class Input {
 public:
  explicit Input(lua_State* L) : terminal_(::isatty(STDIN_FILENO)) {
    if (!terminal_) return;
    completion_state = L;
    rl_readline_name = "asperity";
    rl_catch_signals = 0;  // our SIGINT handler stays in charge (interrupt.cpp)
    rl_attempted_completion_function = complete;
    // '.' and ':' are not word breaks: "asperity.wo<TAB>" completes the whole chain.
    rl_basic_word_break_characters = const_cast<char*>(" \t\n\"\\'><=;+-*/%^~#&|{}()[],");
    rl_completion_append_character = '\0';
    history_ = history_path();
    using_history();
    stifle_history(2000);
    // append_history() only appends to an existing file: create it on the first session.
    if (read_history(history_.c_str()) != 0) write_history(history_.c_str());
  }
  ~Input() {
    if (!terminal_) return;
    history_truncate_file(history_.c_str(), 2000);
    completion_state = nullptr;
  }
  Input(const Input&) = delete;
  Input& operator=(const Input&) = delete;

  bool terminal() const { return terminal_; }

  // One line; `prompt` shows on a terminal only, where Ctrl-C gives Read::interrupt.
  Read read(const char* prompt, std::string& line) {
    if (terminal_) return read_terminal(prompt, line);
    return std::getline(std::cin, line) ? Read::line : Read::eof;
  }

  // A chunk that was run or refused (not one still going on) joins the history.
  void remember(const std::string& chunk) {
    if (!terminal_) return;
    add_history(chunk.c_str());
    append_history(1, history_.c_str());
  }

 private:
  bool terminal_;
  std::string history_;
};

// ---------------------------------------------------------------------------------------------
// Compiling, running, printing

int load(lua_State* L, std::string_view code) {
  return luaL_loadbufferx(L, code.data(), code.size(), "=stdin", "t");
}

// The parser stopped at the end of the input: more lines may complete it.
bool incomplete(lua_State* L, int status) {
  if (status != LUA_ERRSYNTAX) return false;
  std::size_t n = 0;
  const char* msg = lua_tolstring(L, -1, &n);
  const char eof[] = "<eof>";
  return msg && n >= sizeof eof - 1 && std::strcmp(msg + n - (sizeof eof - 1), eof) == 0;
}

enum class Compiled { ok, more, error };

// ok: the chunk's function is on the stack; error: its syntax error is; more: nothing is, the
// chunk may go on on the next line.
Compiled compile(lua_State* L, std::string_view chunk) {
  if (chunk.front() == '=') chunk.remove_prefix(1);  // lua.c's "=x": x prints its value anyway
  int status = load(L, "return " + std::string(chunk) + ";");
  if (status == LUA_OK) return Compiled::ok;
  // "{1," is not yet a statement but may become an expression: wait for more as well.
  bool expression_incomplete = incomplete(L, status);
  lua_pop(L, 1);
  status = load(L, chunk);
  if (status == LUA_OK) return Compiled::ok;
  if (!incomplete(L, status) && !expression_incomplete) return Compiled::error;
  lua_pop(L, 1);
  return Compiled::more;
}

void print_results(lua_State* L, int n) {
  if (n <= 0) return;
  lua_getfield(L, LUA_REGISTRYINDEX, "asperity.show");
  lua_insert(L, -n - 1);
  if (lua_pcall(L, n, 0, 0) != LUA_OK) {
    std::fprintf(stderr, "error printing the result: %s\n", lua_tostring(L, -1));
    lua_pop(L, 1);
  }
  std::fflush(stdout);
}

// Prints the error value on top of the stack and pops it. A Ctrl-C is not a bug: its message
// alone, without the traceback.
void report(lua_State* L) {
  int value = lua_gettop(L);
  const char* msg = is_interruption(L, value) ? luaL_tolstring(L, value, nullptr) : lua_tostring(L, value);
  std::fprintf(stderr, "%s\n", msg ? msg : "(error object without a message)");
  lua_settop(L, value - 1);
}

// Runs the function on top of the stack and prints what it returns; false if it failed.
bool run(lua_State* L) {
  int base = lua_gettop(L) - 1;
  clear_interrupts();
  if (call_with_traceback(L, 0, LUA_MULTRET) != LUA_OK) {
    report(L);
    return false;
  }
  print_results(L, lua_gettop(L) - base);
  lua_settop(L, base);
  return true;
}

// lua.c's doREPL: read, compile (or read on), run, print, until the input ends.
int loop(lua_State* L, Input& in) {
  std::string chunk;
  bool failed = false, last_was_interrupt = false;
  for (;;) {
    std::string line;
    Read r = in.read(chunk.empty() ? "> " : ">> ", line);
    if (r == Read::interrupt) {
      if (last_was_interrupt) break;
      last_was_interrupt = true;
      chunk.clear();
      std::printf("(Ctrl-C again to exit)\n");
      continue;
    }
    last_was_interrupt = false;
    if (r == Read::eof) {
      if (in.terminal()) {
        std::printf("\n");
      } else if (!chunk.empty()) {
        // Input ended inside a chunk: what the parser says about it.
        if (load(L, chunk) != LUA_OK) report(L);
        else lua_pop(L, 1);
        failed = true;
      }
      break;
    }
    chunk = chunk.empty() ? line : chunk + "\n" + line;
    if (chunk.find_first_not_of(" \t\r") == std::string::npos) {
      chunk.clear();
      continue;
    }
    Compiled c = compile(L, chunk);
    if (c == Compiled::more) continue;
    in.remember(chunk);
    if (c == Compiled::ok) {
      failed = !run(L) || failed;
    } else {
      report(L);
      failed = true;
    }
    chunk.clear();
  }
  return in.terminal() || !failed ? 0 : 1;
}

}  // namespace

int repl(Session& session) {
  lua_State* L = session.state();
  Input in(L);
  install_interrupt_handler(L);
  if (in.terminal()) {
    std::printf("%s", version_text().c_str());
    std::printf("help() lists the API; Ctrl-C stops a run; Ctrl-D (or Ctrl-C twice) exits.\n");
  }
  return loop(L, in);
}

}  // namespace asperity::lua
