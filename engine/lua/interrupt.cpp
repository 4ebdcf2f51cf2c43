// SIGINT handling; see interrupt.hpp for the behaviour.
#include "lua/interrupt.hpp"

#include <atomic>
#include <csignal>

#include "asperity/world.hpp"

namespace asperity::lua {

namespace {
std::atomic<World*> running{nullptr};
std::atomic<lua_State*> state{nullptr};
std::atomic<bool> run_interrupted{false};
std::atomic<bool> at_prompt{false};
std::atomic<bool> prompt_interrupted{false};
std::atomic<int> pending{0};  // interrupts not yet served

void interrupt_hook(lua_State* L, lua_Debug*) {
  lua_sethook(L, nullptr, 0, 0);
  run_interrupted = false;
  pending = 0;
  luaL_error(L, "interrupted");
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
