// SIGINT handling; see interrupt.hpp for the behaviour.
#include "lua/interrupt.hpp"

#include <atomic>
#include <csignal>
#include <cstdio>

#include "asperity/world.hpp"
#include "lua/binding.hpp"

namespace asperity::lua {

namespace {
constexpr const char* kInterruptedType = "asperity.Interrupted";

std::atomic<World*> running{nullptr};
std::atomic<lua_State*> state{nullptr};
std::atomic<bool> run_interrupted{false};
std::atomic<bool> at_prompt{false};
std::atomic<bool> prompt_interrupted{false};
std::atomic<int> pending{0};  // interrupts not yet served

void interrupt_hook(lua_State* L, lua_Debug*) {
  lua_sethook(L, nullptr, 0, 0);
  // Raise only an interruption not yet served: the signal may be delivered to another thread of
  // the process (an OpenMP worker), whose lua_sethook can then land after this hook or
  // take_run_interrupt served the interruption; such a late hook only removes itself.
  if (!run_interrupted.exchange(false)) return;
  pending = 0;
  // Where the Lua code was: the innermost frame with a line (the hook may fire in a C function,
  // or in a Lua function whose caller is one, like pcall's).
  int level = 0;
  for (lua_Debug ar; lua_getstack(L, level, &ar); ++level)
    if (lua_getinfo(L, "l", &ar) && ar.currentline > 0) break;
  luaL_where(L, level);
  lua_pushstring(L, "interrupted");
  lua_concat(L, 2);
  make_interruption(L);
  lua_error(L);
}

void on_sigint(int) {
  if (at_prompt.load()) {
    prompt_interrupted = true;
    return;
  }
  if (pending.fetch_add(1) > 0) {
    // Nothing served the first one: give the user the default (terminate).
    std::signal(SIGINT, SIG_DFL);
    std::raise(SIGINT);
    return;
  }
  // All three, because the signal may land anywhere: inside World::cycle (request_stop), in
  // the C++ of world:run between two chunks (the flag, checked after every chunk), or in Lua
  // code (the hook). Whichever serves it first clears the others (take_run_interrupt).
  run_interrupted = true;
  if (World* w = running.load()) w->request_stop();
  if (lua_State* L = state.load())
    lua_sethook(L, interrupt_hook, LUA_MASKCALL | LUA_MASKRET | LUA_MASKCOUNT, 1);
}
}  // namespace

// ---------------------------------------------------------------------------------------------
// The error value

namespace {

int interruption_tostring(lua_State* L) {
  luaL_checktype(L, 1, LUA_TTABLE);
  lua_getfield(L, 1, "message");
  return 1;
}

// "text " .. err works as it does with an error message that is a string.
int interruption_concat(lua_State* L) {
  luaL_tolstring(L, 1, nullptr);
  luaL_tolstring(L, 2, nullptr);
  lua_concat(L, 2);
  return 1;
}

void push_interruption_metatable(lua_State* L) {
  if (luaL_newmetatable(L, kInterruptedType)) {
    static const luaL_Reg meta[] = {{"__tostring", interruption_tostring},
                                    {"__concat", interruption_concat},
                                    {nullptr, nullptr}};
    luaL_setfuncs(L, meta, 0);
  }
}

int l_is_interrupted(lua_State* L) {
  lua_pushboolean(L, is_interruption(L, 1));
  return 1;
}

// SIGTERM, caught on request by a script that saves its state before it goes (a batch system's
// time limit, a study runner stopping its runs): while caught, the signal only sets a flag that
// the script polls at its own safe points; when the catch ends, a request it did not serve ends
// the process as the signal would have.
std::atomic<bool> terminate_flag{false};
bool terminate_caught = false;

void on_sigterm(int) { terminate_flag = true; }

void end_as_terminated() {
  std::fflush(nullptr);
  std::signal(SIGTERM, SIG_DFL);
  std::raise(SIGTERM);
}

int l_catch_terminate(lua_State* L) {
  luaL_checktype(L, 1, LUA_TBOOLEAN);
  const bool on = lua_toboolean(L, 1);
  if (on && !terminate_caught) {
    struct sigaction sa {};
    sa.sa_handler = on_sigterm;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;  // the script's file writes go on undisturbed
    sigaction(SIGTERM, &sa, nullptr);
  } else if (!on && terminate_caught) {
    std::signal(SIGTERM, SIG_DFL);
    if (terminate_flag.load()) end_as_terminated();
  }
  terminate_caught = on;
  return 0;
}

int l_terminate_requested(lua_State* L) {
  lua_pushboolean(L, terminate_flag.load());
  return 1;
}

int l_terminate(lua_State*) {
  end_as_terminated();
  return 0;
}

}  // namespace

void make_interruption(lua_State* L) {
  lua_createtable(L, 0, 2);
  lua_insert(L, -2);
  lua_setfield(L, -2, "message");
  push_interruption_metatable(L);
  lua_setmetatable(L, -2);
}

bool is_interruption(lua_State* L, int index) {
  if (!lua_getmetatable(L, index)) return false;
  luaL_getmetatable(L, kInterruptedType);
  bool same = lua_rawequal(L, -1, -2);
  lua_pop(L, 2);
  return same;
}

void open_interrupt(lua_State* L) {
  push_interruption_metatable(L);
  lua_pop(L, 1);
  static const Function fns[] = {
      {"is_interrupted", l_is_interrupted, "asperity.is_interrupted(err) -> boolean",
       "Whether an error value (from pcall) is a Ctrl-C rather than a failure. An interruption\n"
       "is an error object, not a string: tostring(err) gives its message, \"file:line:\n"
       "interrupted ...\". A failure whose message says \"interrupted\" is not one."},
      {"catch_terminate", l_catch_terminate, "asperity.catch_terminate(on)",
       "true: a SIGTERM (a batch job's time limit, kill) only sets a flag, read by\n"
       "asperity.terminate_requested(), so the script can save its state at a safe point and\n"
       "then call asperity.terminate(). false: the default again; a request not served ends\n"
       "the process now, as the signal would have."},
      {"terminate_requested", l_terminate_requested, "asperity.terminate_requested() -> boolean",
       "Whether a SIGTERM arrived while caught (asperity.catch_terminate)."},
      {"terminate", l_terminate, "asperity.terminate()",
       "Ends the process as a SIGTERM does (exit status 143 in a shell), output flushed: after a\n"
       "script saved its state on asperity.terminate_requested()."}};
  register_functions(L, -1, fns);
}

// ---------------------------------------------------------------------------------------------
// The signal

void install_interrupt_handler(lua_State* L) {
  state = L;
  struct sigaction sa {};
  sa.sa_handler = on_sigint;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: the REPL's select() must see EINTR
  sigaction(SIGINT, &sa, nullptr);
}

void remove_interrupt_handler() {
  std::signal(SIGINT, SIG_DFL);
  state = nullptr;
}

RunningWorld::RunningWorld(World& world) { running = &world; }
RunningWorld::~RunningWorld() { running = nullptr; }

bool take_run_interrupt() {
  if (run_interrupted.exchange(false)) {
    // Served here: the hook must not raise a second error later (it would fire inside the
    // error's message handler).
    if (lua_State* L = state.load()) lua_sethook(L, nullptr, 0, 0);
    pending = 0;
    return true;
  }
  return false;
}

void clear_interrupts() {
  run_interrupted = false;
  prompt_interrupted = false;
  pending = 0;
  if (lua_State* L = state.load()) lua_sethook(L, nullptr, 0, 0);
}

void set_at_prompt(bool value) { at_prompt = value; }
bool take_prompt_interrupt() { return prompt_interrupted.exchange(false); }

}  // namespace asperity::lua
