// world: running (cycle, run with its stop conditions and progress line, time step, threads).
#include <cmath>
#include <cstdio>
#include <limits>

#include "asperity/world.hpp"
#include "lua/binding.hpp"
#include "lua/interrupt.hpp"
#include "lua/progress.hpp"
#include "lua/wrap_world.hpp"

namespace asperity::lua {

namespace {

// ---------------------------------------------------------------------------------------------
// Running

[[noreturn]] void throw_interrupted(const World& w) {
  throw Interrupted("interrupted at step " + std::to_string(w.step_count()) +
                    " (the world is intact: continue with world:cycle or world:run)");
}

std::uint64_t cycle_checked(World& w, std::uint64_t n) {
  std::uint64_t done;
  {
    RunningWorld running(w);
    done = w.cycle(n);
  }
  if (take_run_interrupt() || done < n) throw_interrupted(w);
  return done;
}

int world_cycle(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    lua_Integer n = opt_integer(L, 2, 1);
    if (n < 0) throw ArgError{2, "the number of steps must be >= 0"};
    lua_pushinteger(L, static_cast<lua_Integer>(cycle_checked(w, static_cast<std::uint64_t>(n))));
    return 1;
  });
}

// Calls fn(world) with `nresults` results, re-raising its error unchanged.
void call_with_world(lua_State* L, int fn, int nresults) {
  lua_pushvalue(L, fn);
  lua_pushvalue(L, 1);
  if (lua_pcall(L, 1, nresults, 0) != LUA_OK) throw PendingLuaError{};
}

// The value shown in the progress line: a string, or a table of name = value.
std::string show_text(lua_State* L, int fn) {
  call_with_world(L, fn, 1);
  std::string out;
  if (lua_type(L, -1) == LUA_TSTRING) {
    out = lua_tostring(L, -1);
  } else if (lua_type(L, -1) == LUA_TTABLE) {
    lua_pushnil(L);
    while (lua_next(L, -2)) {
      if (lua_type(L, -2) == LUA_TSTRING) {
        char buf[48];
        if (lua_type(L, -1) == LUA_TNUMBER) std::snprintf(buf, sizeof buf, "%.4g", lua_tonumber(L, -1));
        else if (lua_type(L, -1) == LUA_TSTRING) std::snprintf(buf, sizeof buf, "%s", lua_tostring(L, -1));
        else std::snprintf(buf, sizeof buf, "%s", luaL_typename(L, -1));
        out += (out.empty() ? "" : "  ") + std::string(lua_tostring(L, -2)) + "=" + buf;
      }
      lua_pop(L, 1);
    }
  }
  lua_pop(L, 1);
  return out;
}

int world_run(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    const std::string ctx = "world:run";
    Options o(L, 2, ctx, 2);
    lua_Integer steps = o.integer("steps", 0);
    if (o.present("steps") && steps <= 0) throw Error(ctx + ": option 'steps' must be > 0");
    int stop_type = o.push("stop_when");
    int stop_fn = lua_gettop(L);
    bool equilibrium = false;
    if (stop_type == LUA_TSTRING) {
      std::string s = lua_tostring(L, -1);
      if (s != "equilibrium")
        throw Error(ctx + ": option 'stop_when' must be a function(world) or \"equilibrium\", got \"" + s + "\"");
      equilibrium = true;
    } else if (stop_type != LUA_TFUNCTION && stop_type != LUA_TNIL) {
      throw Error(ctx + ": option 'stop_when' must be a function(world) or \"equilibrium\", got " +
                  type_name(L, -1));
    }
    double ratio = o.number("ratio", 1e-4);
    if (o.present("ratio") && !equilibrium)
      throw Error(ctx + ": option 'ratio' applies only with stop_when = \"equilibrium\"");
    if (!(ratio > 0)) throw Error(ctx + ": option 'ratio' must be > 0");
    lua_Integer every = o.integer("every", 100);
    if (every < 1) throw Error(ctx + ": option 'every' must be >= 1");
    int callback_type = o.push_checked("callback", LUA_TFUNCTION, "a function(world)");
    int callback = lua_gettop(L);
    lua_Integer sample_every = o.integer("sample_every", 0);
    int sample_type = o.push_checked("sample", LUA_TFUNCTION, "a function(world)");
    int sample = lua_gettop(L);
    if (sample_type != LUA_TNIL && sample_every < 1)
      throw Error(ctx + ": option 'sample' needs sample_every = (steps between samples, >= 1)");
    if (sample_type == LUA_TNIL && o.present("sample_every"))
      throw Error(ctx + ": option 'sample_every' needs sample = (a function(world))");
    lua_Integer steps_done = o.integer("steps_done", 0);
    if (steps_done < 0) throw Error(ctx + ": option 'steps_done' must be >= 0");
    if (steps > 0 && steps_done >= steps)
      throw Error(ctx + ": option 'steps_done' (" + std::to_string(steps_done) + ") must be below steps (" +
                  std::to_string(steps) + ")");
    bool progress = o.boolean("progress", true);
    int show_type = o.push_checked("show", LUA_TFUNCTION, "a function(world) returning a string or table");
    int show = lua_gettop(L);
    int fraction_type = o.push_checked("fraction", LUA_TFUNCTION, "a function(world) returning 0..1");
    int fraction_fn = lua_gettop(L);
    o.finish();
    if (steps == 0 && stop_type == LUA_TNIL)
      throw Error(ctx + ": give steps = (how many) and/or stop_when = (a function or \"equilibrium\")");

    RunPlan plan;
    plan.steps = static_cast<std::uint64_t>(steps);
    plan.until_equilibrium = equilibrium;
    plan.ratio = ratio;
    plan.every = static_cast<std::uint64_t>(every);
    plan.steps_done = static_cast<std::uint64_t>(steps_done);
    if (callback_type != LUA_TNIL) plan.callback = [&] { call_with_world(L, callback, 0); };
    if (sample_type != LUA_TNIL) {
      plan.sample_every = static_cast<std::uint64_t>(sample_every);
      plan.sample = [&] { call_with_world(L, sample, 0); };
    }
    if (stop_type == LUA_TFUNCTION)
      plan.stop_when = [&] {
        call_with_world(L, stop_fn, 1);
        const bool stop = lua_toboolean(L, -1);
        lua_pop(L, 1);
        return stop;
      };
    plan.interrupted = take_run_interrupt;
    // With a stop condition the step count is only a cap: no percent or ETA from it (a script's
    // fraction gives them).
    Progress bar(progress, stop_type == LUA_TNIL ? plan.steps : 0, LogCadence::from_environment());
    plan.on_chunk = [&](std::uint64_t done, double last_ratio) {
      if (!bar.due()) return;
      std::string extra;
      if (equilibrium && !std::isnan(last_ratio)) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "ratio=%.3g (target %.3g)", last_ratio, ratio);
        extra = buf;
      }
      if (show_type != LUA_TNIL) {
        std::string text = show_text(L, show);
        if (!text.empty()) extra += (extra.empty() ? "" : "  ") + text;
      }
      double fraction = -1;
      if (fraction_type != LUA_TNIL) {
        call_with_world(L, fraction_fn, 1);
        fraction = lua_isnumber(L, -1) ? std::max(0.0, static_cast<double>(lua_tonumber(L, -1))) : -1;
        lua_pop(L, 1);
      }
      bar.draw(done, extra, fraction);
    };
    RunResult r;
    {
      RunningWorld running(w);  // a Ctrl-C stops the engine's step (interrupt.hpp)
      r = w.run(plan);
    }
    if (r.end == RunResult::End::interrupted) throw_interrupted(w);
    static const char* const reasons[] = {"steps", "equilibrium", "stop_when"};
    const char* reason = reasons[static_cast<int>(r.end)];
    bar.finish(r.steps, reason);
    lua_pushinteger(L, static_cast<lua_Integer>(r.steps));
    lua_pushstring(L, reason);
    return 2;
  });
}

int world_dt(lua_State* L) {
  return guarded(L, [&] { lua_pushnumber(L, world_arg(L).dt()); return 1; });
}
// world:set_dt(x), world:set_dt_safety(x), world:set_skin(x): one number, checked by the World.
template <void (World::*Set)(double)>
int set_world_number(lua_State* L) {
  return guarded(L, [&] {
    (world_arg(L).*Set)(check_number(L, 2));
    return 0;
  });
}
int world_set_rotation_lock_beams(lua_State* L) {
  return guarded(L, [&] {
    world_arg(L).set_rotation_lock_beams(check_boolean(L, 2));
    return 0;
  });
}
int world_critical_dt(lua_State* L) {
  return guarded(L, [&] { lua_pushnumber(L, world_arg(L).critical_dt()); return 1; });
}
int world_step(lua_State* L) {
  return guarded(L, [&] {
    lua_pushinteger(L, static_cast<lua_Integer>(world_arg(L).step_count()));
    return 1;
  });
}
int world_time(lua_State* L) {
  return guarded(L, [&] { lua_pushnumber(L, world_arg(L).time()); return 1; });
}
int world_set_threads(lua_State* L) {
  return guarded(L, [&] {
    World& w = world_arg(L);
    w.set_threads(int_in(check_integer(L, 2), "world:set_threads: threads", 0, kMaxThreads));
    return 0;
  });
}
int world_simd(lua_State* L) {
  return guarded(L, [&] {
    std::string s = world_arg(L).simd_architecture();
    lua_pushstring(L, s.c_str());
    return 1;
  });
}
int world_stats(lua_State* L) {
  return guarded(L, [&] {
    StepStats s = world_arg(L).stats();
    lua_createtable(L, 0, 8);
    auto put = [&](const char* k, std::uint64_t v) {
      lua_pushinteger(L, static_cast<lua_Integer>(v));
      lua_setfield(L, -2, k);
    };
    put("rebuilds", s.rebuilds);
    put("reorders", s.reorders);
    put("pairs", s.pairs);
    put("contacts", s.contacts);
    put("wall_contacts", s.wall_contacts);
    put("frozen_bonds", s.frozen_bonds);
    put("threads", std::uint64_t(s.threads));
    if (s.busy_elsewhere >= 0) {  // nil where not measured
      lua_pushnumber(L, s.busy_elsewhere);
      lua_setfield(L, -2, "busy_elsewhere");
    }
    return 1;
  });
}
int world_rebuild_neighbors(lua_State* L) {
  return guarded(L, [&] {
    world_arg(L).rebuild_neighbors();
    return 0;
  });
}

}  // namespace

std::span<const Function> world_run_methods() {
  static const Function methods[] = {
      {"cycle", world_cycle, "world:cycle([n]) -> steps",
       "Advances n steps (1). Ctrl-C stops it at the next step with an interruption (asperity.is_interrupted(err) is true)."},
      {"run", world_run,
       "world:run{steps= [, stop_when=] [, ratio=] [, every=] [, callback=] [, progress=] [, show=]\n"
       "          [, fraction=] [, sample_every=, sample=] [, steps_done=]}\n"
       "  -> steps, reason",
       "Runs up to `steps` steps, or until stop_when: a function(world) returning true, or\n"
       "\"equilibrium\" (unbalanced-force ratio <= ratio, default 1e-4). stop_when and\n"
       "callback(world) are evaluated every `every` steps (100). sample(world) is called every\n"
       "`sample_every` steps, on its own cadence, before the callback when both are due: a fine\n"
       "series (world:energies() reads without changing the run) without checking the stop as\n"
       "often. A progress line appears on a terminal after 2 s, and in a log (stderr not a\n"
       "terminal) after 1 minute and then every 5 (ASPERITY_PROGRESS_EVERY=S: every S s;\n"
       "progress=false: never); show(world) returns a string or a table of values to add to it;\n"
       "fraction(world) returns the completion 0..1 for the percent and ETA when stop_when, not\n"
       "steps, ends the run (with stop_when, steps is only a cap and gives neither).\n"
       "steps_done: steps of this run done before (a run resumed from a checkpoint): the cap and\n"
       "the cadences count on from there, so hooks run at the steps an unbroken run's would.\n"
       "reason: \"steps\", \"equilibrium\" or \"stop_when\"."},
      {"dt", world_dt, "world:dt() -> s", "The time step in use."},
      {"set_dt", set_world_number<&World::set_dt>, "world:set_dt(dt)", "Fixes the time step (0: automatic again)."},
      {"set_dt_safety", set_world_number<&World::set_dt_safety>, "world:set_dt_safety(f)",
       "Automatic time step = f x the critical estimate (default 0.8; 0.001 <= f <= 2)."},
      {"set_skin", set_world_number<&World::set_skin>, "world:set_skin(m)", "Verlet skin in m (the list is rebuilt); 0: automatic again, 0.4 x the mean radius at the next build."},
      {"set_rotation_lock_bonds", set_world_number<&World::set_rotation_lock_bonds>, "world:set_rotation_lock_bonds(k)",
       "A particle with a bond does not rotate; once one of its bonds broke, only while it holds k\n"
       "(1: the thesis's rule, every bonded particle locked; model.md 2)."},
      {"set_rotation_lock_beams", world_set_rotation_lock_beams, "world:set_rotation_lock_beams(b)",
       "true: only a bond whose parallel bond holds locks its particles' rotation; false (the default):\n"
       "a bond either part of which holds, the contact bond alone too (model.md 5)."},
      {"set_overlap_limit", set_world_number<&World::set_overlap_limit>, "world:set_overlap_limit(r)",
       "The health check's deepest overlap, in radii of the smaller body (default 1; 0 < r < 2).\n"
       "Deeper, one centre is inside the other particle; a rigid block's contacts may go there."},
      {"set_friction", set_world_number<&World::set_friction>, "world:set_friction(mu)",
       "Ball-ball Coulomb coefficient from the next step on (walls keep theirs)."},
      {"set_damping", set_world_number<&World::set_damping>, "world:set_damping(alpha)",
       "Local (Cundall) damping [3-28] from the next step on, 0 <= alpha < 1 (groups with their own keep it)."},
      {"critical_dt", world_critical_dt, "world:critical_dt() -> s",
       "Critical time step estimate now, without the safety factor."},
      {"step", world_step, "world:step() -> n", "Steps done so far."},
      {"time", world_time, "world:time() -> s", "Simulated time."},
      {"set_threads", world_set_threads, "world:set_threads(n)", "OpenMP threads (0: automatic, by the number of pairs and bonds, up to the cores that other processes leave free)."},
      {"simd", world_simd, "world:simd() -> name", "SIMD architecture of the kernels."},
      {"stats", world_stats, "world:stats() -> table", "Rebuilds, reorders, pairs, contacts, wall_contacts, frozen_bonds (bonds inside a rigid group that does not turn, which the step leaves out); threads (of the next step) and, with automatic threads, busy_elsewhere (cores other processes kept busy lately, which the count leaves to them)."},
      {"rebuild_neighbors", world_rebuild_neighbors, "world:rebuild_neighbors()", "Rebuilds the pair list now."},
  };
  return methods;
}

}  // namespace asperity::lua
