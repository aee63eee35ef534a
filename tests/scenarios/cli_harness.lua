-- cli_harness.lua: the scene-test harness (lua/wobble/test.lua) tested with itself.

-- the "file:line: " of the line that calls here()
local function here() local _, e = pcall(error, "", 3); return e end

test("near, rel: pass within the tolerance", function()
  expect.near(1.0005, 1, 1e-3)
  expect.near(-2, -2, 0)
  expect.rel(101, 100, 0.02)
  expect.rel(-99, -100, 0.02)
  expect.rel(0, 0, 0.1)
end)

test("near, rel: fail outside, NaN never passes, the shortest digits that read back", function()
  expect.error(function() expect.near(1.5, 1, 0.1) end, "expected 1 +- 0.1, got 1.5 (off by 0.5)")
  expect.error(function() expect.near(0.7, 0.6, 0.01) end, "expected 0.6 +- 0.01, got 0.7 (off by 0.09999999999999998)")
  -- 16 and 17 digits only where fewer would read back as another double
  expect.error(function() expect.near(0.1 + 0.7, 0.5, 0.01) end, "got 0.7999999999999999 ")
  expect.error(function() expect.near(0.1 + 0.2, 0.3, 0) end, "got 0.30000000000000004")
  expect.error(function() expect.near(0 / 0, 0, 1) end, "got nan")
  expect.error(function() expect.near(nil, 0, 1) end, "expected a number near 0, got nil")
  expect.error(function() expect.rel(103, 100, 0.02) end, "within 0.02 relative, got 103")
  expect.error(function() expect.rel(1e-300, 0, 0.1) end, "expected 0 within")
end)

test("failures name the line of the expect call", function()
  local at, err = here(), expect.error(function() expect.eq(1, 2) end)
  expect.eq(err, at .. "expected 2, got 1")
  expect.truthy(at:find("cli_harness.lua:%d+: $"), at)
end)

test("eq: values, deep tables, cycles", function()
  expect.eq(3, 3)
  expect.eq("a", "a")
  expect.eq(1, 1.0)
  expect.eq({ 1, { 2, { x = 3 } } }, { 1, { 2, { x = 3 } } })
  local a, b = {}, {}
  a.self, b.self = a, b
  expect.eq(a, b)
  expect.error(function() expect.eq({ 1, 2, 3 }, { 1, 2, 4 }) end, "expected {1, 2, 4}, got {1, 2, 3} (differs at [3])")
  expect.error(function() expect.eq({ x = { y = 1 } }, { x = { y = 2 } }) end, "differs at [\"x\"][\"y\"]")
  expect.error(function() expect.eq({ 1 }, { 1, 2 }) end, "differs at [2]")
  expect.error(function() expect.eq("1", 1) end, 'expected 1, got "1"')
  expect.error(function() expect.eq(0 / 0, 0 / 0) end, "expected nan, got nan")
end)

test("truthy, falsy", function()
  expect.truthy(0)
  expect.truthy("")
  expect.falsy(nil)
  expect.falsy(false)
  expect.error(function() expect.truthy(nil) end, "expected a true value, got nil")
  expect.error(function() expect.falsy(0) end, "expected false or nil, got 0")
end)

test("lt, le, gt, ge", function()
  expect.lt(1, 2)
  expect.le(2, 2)
  expect.gt(3, 2.5)
  expect.ge(2, 2)
  expect.lt("a", "b")
  expect.error(function() expect.lt(2, 1) end, "expected 2 < 1")
  expect.error(function() expect.le(3, 2) end, "expected 3 <= 2")
  expect.error(function() expect.gt(1, 1) end, "expected 1 > 1")
  expect.error(function() expect.ge(1, 2) end, "expected 1 >= 2")
  expect.error(function() expect.lt(nil, 1) end, "expected nil < 1")
  expect.error(function() expect.lt(0 / 0, 1) end, "expected nan < 1")
end)

test("error: plain text first, then a Lua pattern", function()
  expect.error(function() error("a.b(c") end, "a.b(c")           -- literal: ( alone is no pattern
  expect.error(function() error("value 42 too big") end, "value %d+ too")
  expect.error(function() error({}) end, "table:")                -- non-string errors: tostring
  local err = expect.error(function() error("returned", 0) end)  -- no pattern: must raise
  expect.eq(err, "returned")
  expect.error(function() expect.error(function() end) end, "expected an error, but the function returned normally")
  expect.error(function() expect.error(function() error("abc") end, "xyz") end,
               'expected an error matching "xyz", got ')
  expect.error(function() expect.error(function() error("abc") end, "[") end, "matching \"[\"")  -- bad pattern
end)

test("finite: every value, trailing message", function()
  expect.finite(1)
  expect.finite(1, 2.5, -3)
  expect.error(function() expect.finite(1 / 0) end, "expected a finite number, got inf")
  expect.error(function() expect.finite(1, 0 / 0, 3) end, "(value 2), got nan")
  expect.error(function() expect.finite("1") end, 'got "1"')
  expect.error(function() expect.finite(-1 / 0, "speed") end, "speed: expected a finite number, got -inf")
  expect.error(function() expect.finite() end, "got nothing")
end)

test("a message argument comes first in the failure", function()
  expect.error(function() expect.eq(1, 2, "the answer") end, "the answer: expected 2, got 1")
  expect.error(function() expect.near(1, 2, 0.5, "height") end, "height: expected 2")
  expect.error(function() expect.lt(2, 1, "order") end, "order: expected 2 < 1")
end)

test("misusing expect is an error, not a silent pass", function()
  expect.error(function() expect.near(1, "x", 0.1) end, "bad argument to 'expect.near'")
  expect.error(function() expect.near(1, 1, nil) end, "tolerance must be a number")
  expect.error(function() expect.error(42) end, "function expected")
end)

test("test() inside a case is refused; names are checked", function()
  expect.error(function() test("nested", function() end) end, "inside a test case")
  expect.error(function() test(1, function() end) end, "bad argument #1 to 'test'")
  expect.error(function() test("x", 1) end, "bad argument #2 to 'test'")
end)

test("a failure caught by expect.error does not fail the case", function()
  expect.error(function() expect.eq("a", "b") end, 'expected "b", got "a"')
end)

test("tables print readably", function()
  local show = require("wobble.test").show
  expect.eq(show({ 1, 2, x = true }), "{1, 2, x = true}")
  expect.eq(show(0.1), "0.1")
  expect.eq(show(0.1 + 0.2), "0.30000000000000004")
  expect.eq(show(7), "7")
  expect.eq(show(setmetatable({}, { __tostring = function() return "vec(1,2,3)" end })), "vec(1,2,3)")
end)
