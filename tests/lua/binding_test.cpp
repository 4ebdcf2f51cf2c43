// The Lua binding seen from C++: a Session runs code; errors come back as messages.
#include <gtest/gtest.h>
#include <lua.hpp>

#include <csignal>

#include "lua/session.hpp"

using asperity::lua::Session;

namespace {

// Runs code, expects success.
void ok(Session& s, const std::string& code) {
  std::string error;
  EXPECT_TRUE(s.run_string(code, "=test", &error)) << code << "\n" << error;
}

// Runs code, expects failure with `fragment` in the message; returns the message.
std::string fails(Session& s, const std::string& code, const std::string& fragment) {
  std::string error;
  EXPECT_FALSE(s.run_string(code, "=test", &error)) << code;
  EXPECT_NE(error.find(fragment), std::string::npos) << "message: " << error;
  return error;
}

}  // namespace

TEST(Binding, ModuleIsLoadedAsGlobalAndRequire) {
  Session s;
  ok(s, "assert(asperity and require('asperity') == asperity)");
  ok(s, "assert(type(asperity.version) == 'string' and type(help) == 'function')");
  ok(s, "assert(package.path:find(asperity.scripts_dir .. '/lib/?.lua', 1, true))");
  ok(s, "assert(require('params').defaults{a = 1}.a == 1)");
}

TEST(Binding, ParamsConvertNumbersAndBooleans) {
  Session s;
  s.set_params("x.lua", {{"n", "12"}, {"r", "0.5"}, {"name", "abc"}, {"flag", "false"}});
  ok(s, "assert(params.n == 12 and math.type(params.n) == 'integer')");
  ok(s, "assert(params.r == 0.5 and params.name == 'abc' and params.flag == false)");
  ok(s, "assert(arg[0] == 'x.lua' and arg[1] == 'n=12')");
}

TEST(Binding, ArgumentErrorsNameArgumentAndType) {
  Session s;
  ok(s, "w = asperity.world()");
  fails(s, "w:add_particle({0,0,0}, 'big')", "bad argument #2 to 'add_particle' (number expected, got string)");
  fails(s, "w:add_particle(5, 1)", "bad argument #1 to 'add_particle' (vector {x, y, z} expected, got number)");
  fails(s, "w.cycle(3)", "bad argument #1 to 'cycle' (asperity.World expected, got number)");
  fails(s, "w:cycle(1.5)", "number has no integer representation");
  fails(s, "w:velocity(1)", "no particle 1 (there are none yet)");
}

TEST(Binding, OptionsRejectUnknownAndMistypedFields) {
  Session s;
  fails(s, "asperity.world{gravty = {0,0,-1}}", "unknown option 'gravty' (known options:");
  fails(s, "asperity.world{density = 'x'}", "option 'density' must be a number, got string");
  fails(s, "asperity.world{material = {kn = 1, mu = 0.3}}", "option 'material': unknown option 'mu'");
  fails(s, "asperity.world{simd = 'neon'}", "asperity.world: unknown or unsupported SIMD architecture 'neon' (valid on this CPU: auto, ");
  fails(s, "asperity.world{gravity = 9.81}", "option 'gravity' must be a vector {x, y, z}, got number");
  fails(s, "asperity.world():run{}", "give steps = (how many)");
}

TEST(Binding, CallbackErrorsKeepTheirPosition) {
  Session s;
  ok(s, "w = asperity.world(); w:add_particle({0,0,0}, 0.01)");
  std::string error;
  EXPECT_FALSE(s.run_string("w:run{steps = 10, every = 2,\n callback = function() error('deep') end}", "=cb", &error));
  EXPECT_NE(error.find("cb:2: deep"), std::string::npos) << error;
  EXPECT_NE(error.find("stack traceback"), std::string::npos) << error;
  // the world is still usable after the error
  ok(s, "assert(w:step() == 2); w:cycle(3); assert(w:step() == 5)");
}

// A Ctrl-C while Lua code runs (the signal raised from inside it, so it comes at a known point):
// an interruption, told by its type from a plain error that says "interrupted".
TEST(Binding, InterruptionIsTypedNotWorded) {
  Session s;
  lua_register(s.state(), "sigint", [](lua_State*) {
    std::raise(SIGINT);
    return 0;
  });
  ok(s, "local ok, e = pcall(function() sigint(); return 1 end)\n"
        "assert(not ok and asperity.is_interrupted(e) and tostring(e) == 'test:1: interrupted', tostring(e))");
  std::string error = fails(s, "sigint()\nlocal x = 1", "test:1: interrupted\nstack traceback:");
  EXPECT_TRUE(s.interrupted()) << error;
  fails(s, "error('interrupted')", "test:1: interrupted");
  EXPECT_FALSE(s.interrupted());
  ok(s, "local ok, e = pcall(error, 'interrupted'); assert(not asperity.is_interrupted(e))");
}

TEST(Binding, ArraysAndVectors) {
  Session s;
  ok(s, "a = asperity.array{{1, 2, 3}, {4, 5, 6}}");
  ok(s, "assert(#a == 2 and a[2].y == 5 and select('#', a:row(1)) == 3)");
  ok(s, "local x, y, z = a:sum(); assert(x == 5 and y == 7 and z == 9)");
  ok(s, "assert(a:norms()[1] == math.sqrt(14))");
  ok(s, "a[1] = {0, 0, 0}; assert(a:get(1, 3) == 0)");
  fails(s, "return a[3]", "row 3 out of range 1..2");
  ok(s, "local v = asperity.vec(3, 4, 0); assert(v:norm() == 5 and (v / 5).x == 0.6)");
  ok(s, "assert(tostring(asperity.vec(1, 2, 3)) == '{1, 2, 3}')");
}

TEST(Binding, SeriesRecordsNamedColumns) {
  Session s;
  ok(s, "sr = asperity.series{'time [s]', {'f', 'N'}, 'n'}");
  ok(s, "sr:record{time = 1, f = 2, n = 3}; sr:record(4, 5, 6)");
  ok(s, "assert(sr:rows() == 2 and sr:column('f')[2] == 5 and sr:last('n') == 6)");
  ok(s, "local names, units = sr:names(); assert(names[1] == 'time' and units[1] == 's' and units[3] == '')");
  fails(s, "sr:record{time = 1, f = 2}", "no value for column 'n'");
  fails(s, "sr:record{time = 1, f = 2, n = 3, g = 4}", "unknown column 'g'");
  fails(s, "asperity.series{'a', colour = 'red'}", "unknown option 'colour'");
}

TEST(Binding, JsonFromLuaValues) {
  Session s;
  ok(s, "assert(asperity.json({b = 1, a = {1, 2}}, 0) == '{\"a\":[1, 2],\"b\":1}\\n')");
  fails(s, "asperity.json({f = print})", "cannot write a function (at value.f)");
}

TEST(Binding, HelpDescribesFunctionsAndTypes) {
  Session s;
  ok(s, "assert(asperity.doc(asperity.world):find('asperity.world{', 1, true))");
  ok(s, "assert(asperity.doc(asperity.world()):find('World:', 1, true))");
  ok(s, "assert(asperity.doc(asperity.array(1)):find('Array', 1, true))");
}
