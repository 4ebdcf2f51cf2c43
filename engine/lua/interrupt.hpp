// Ctrl-C (SIGINT) for scripts and the REPL.
//
// What a Ctrl-C does depends on where the program is:
//  - inside World::cycle (the engine is running): World::request_stop(), which the engine checks
//    every step; world:cycle/run then raise an interruption, so a script ends (or a pcall sees
//    it) and the REPL returns to its prompt with the world intact;
//  - running Lua code: a count hook raises an interruption at the next instruction (as lua.c
//    does);
//  - at the REPL prompt: the REPL is told (take_prompt_interrupt) and clears the line; a second
//    Ctrl-C there exits;
//  - a second Ctrl-C before the first was served: the default action (the process ends), for
//    when something does not respond.
// The handler only stores to atomics and calls the two functions documented as safe from a
// signal handler (World::request_stop, lua_sethook).
//
// An interruption is an error value of its own type, not a string: a table {message = text}
// with the metatable "asperity.Interrupted" (__tostring gives the text, "file:line: interrupted
// ..."), so the REPL, `asperity run` and scripts (asperity.is_interrupted) tell a Ctrl-C from a
// failure without reading its words. The message handler of session.cpp leaves it an object
// and adds the traceback to it as the field `traceback`.
#pragma once

#include <lua.hpp>

namespace asperity {
class World;
}

namespace asperity::lua {

void install_interrupt_handler(lua_State* L);
void remove_interrupt_handler();

// Marks the world whose cycle() is running, for the duration of a scope.
class RunningWorld {
 public:
  explicit RunningWorld(World& world);
  ~RunningWorld();
  RunningWorld(const RunningWorld&) = delete;
  RunningWorld& operator=(const RunningWorld&) = delete;
};

// True (once) if a Ctrl-C stopped the engine since the last call.
bool take_run_interrupt();
// Forget any interrupt not yet served (the REPL, before evaluating a new line).
void clear_interrupts();

// Replaces the message (a string) on top of the stack by an interruption carrying it.
void make_interruption(lua_State* L);
bool is_interruption(lua_State* L, int index);

void set_at_prompt(bool at_prompt);
bool take_prompt_interrupt();

}  // namespace asperity::lua
