-- wobble.test: the scene-test harness.
--
-- `wobble test` makes `test` and `expect` globals in every file it runs; anywhere else
--   local T = require "wobble.test"; local test, expect = T.test, T.expect
--
--   test("a particle falls", function()
--     local w = wobble.world{}
--     local p = w:particle{ pos = {0, 1, 0} }
--     w:run{ frames = 60 }
--     local _, y = w:position(p)
--     expect.lt(y, 1)
--   end)
--
-- The runner calls the cases after the file's chunk has run, in order, each in its own
-- protected call. A failed expectation raises an error located at the line that called
-- expect.*; a case that calls no expect.* at all fails ("no expectations"), so a test
-- that checks nothing cannot pass. Every expect.* takes an optional last message that
-- is put in front of the failure text. A failed expectation fails its case even when
-- the script catches the error (pcall, a coroutine): the runner checks _first_failure.
-- The runner also makes print write TAP comments ("# " before every line), so a test's
-- output is never read as a result; a test that makes something write to stderr on
-- purpose says so first, print("expected on stderr: ..."), and tests/run_all.sh checks
-- that no other warning, assertion or error line shows up.

local M = { cases = {}, _count = 0, _running = false, _last_failure = nil, _first_failure = nil }

local type, tostring, select, pcall, error = type, tostring, select, pcall, error
local abs, huge, mtype = math.abs, math.huge, math.type
local fmt, find = string.format, string.find

-- ---- formatting ---------------------------------------------------------------------

local show

-- numbers in the shortest of %.15g, %.16g, %.17g that reads back as the same double
-- (0.6, not 0.59999999999999998); integers as they are
local function num(x)
  if mtype(x) == "integer" then return tostring(x) end
  if x ~= x then return "nan" end
  if x == huge then return "inf" elseif x == -huge then return "-inf" end
  for _, f in ipairs({ "%.15g", "%.16g" }) do
    local s = fmt(f, x)
    if tonumber(s) == x then return s end
  end
  return fmt("%.17g", x)
end

local function show_table(t, depth)
  local mt = getmetatable(t)
  if mt and mt.__tostring then return tostring(t) end
  if depth > 2 then return "{...}" end
  local parts, n = {}, #t
  for i = 1, n do
    if i > 8 then parts[#parts + 1] = "..."; break end
    parts[#parts + 1] = show(t[i], depth + 1)
  end
  local extra = 0
  for k, v in pairs(t) do
    if not (mtype(k) == "integer" and k >= 1 and k <= n) then
      extra = extra + 1
      if extra > 8 then parts[#parts + 1] = "..."; break end
      local key = type(k) == "string" and k:match("^[%a_][%w_]*$") and k or "[" .. show(k, depth + 1) .. "]"
      parts[#parts + 1] = key .. " = " .. show(v, depth + 1)
    end
  end
  return "{" .. table.concat(parts, ", ") .. "}"
end

function show(v, depth)
  local t = type(v)
  if t == "number" then return num(v) end
  if t == "string" then return fmt("%q", v) end
  if t == "table" then return show_table(v, depth or 1) end
  return tostring(v)
end

-- ---- failing ----------------------------------------------------------------------

-- "file:line: " of the code that called expect.*: the level error() counts from its
-- caller: 1 pcall, 2 where, 3 fail, 4 expect.x, 5 the code that called expect.x. When
-- that is a C function (pcall(expect.eq, 1, 2)) the Lua code that called it is named.
local function where()
  for level = 5, 12 do
    local _, e = pcall(error, "", level)
    if type(e) ~= "string" then break end
    if e ~= "" then return e end
  end
  return ""
end

-- every expect.* calls fail directly (never as a tail call), so the level is fixed
local function fail(msg, user)
  if user ~= nil then msg = tostring(user) .. ": " .. msg end
  local full = where() .. msg
  M._last_failure = full  -- lets the runner tell a failed expectation from a script error
  if M._first_failure == nil then M._first_failure = full end  -- survives a pcall around expect.*
  error(full, 0)
end

local function count() M._count = M._count + 1 end

-- misuse of expect itself (wrong argument types) is an error at the caller, not a failure
local function need_number(v, what, fname)
  if type(v) ~= "number" then
    error(fmt("bad argument to 'expect.%s': %s must be a number, got %s", fname, what, type(v)), 3)
  end
end

-- ---- expectations -----------------------------------------------------------------

local expect = {}

-- |actual - expected| <= tol
function expect.near(actual, expected, tol, msg)
  count()
  need_number(expected, "expected", "near"); need_number(tol, "tolerance", "near")
  if type(actual) ~= "number" then
    fail(fmt("expected a number near %s, got %s", num(expected), show(actual)), msg)
  elseif not (abs(actual - expected) <= tol) then
    fail(fmt("expected %s +- %s, got %s (off by %s)", num(expected), num(tol), num(actual),
             num(actual - expected)), msg)
  end
end

-- |actual - expected| <= reltol * |expected| (so expected = 0 asks for exactly 0)
function expect.rel(actual, expected, reltol, msg)
  count()
  need_number(expected, "expected", "rel"); need_number(reltol, "relative tolerance", "rel")
  if type(actual) ~= "number" then
    fail(fmt("expected a number near %s, got %s", num(expected), show(actual)), msg)
  elseif not (abs(actual - expected) <= reltol * abs(expected)) then
    local r = expected ~= 0 and abs(actual - expected) / abs(expected) or huge
    fail(fmt("expected %s within %s relative, got %s (relative error %s)", num(expected), num(reltol),
             num(actual), num(r)), msg)
  end
end

-- deep equality: "" when equal, else where the first difference is ("[2].x")
local function diff(a, b, seen)
  if a == b then return "" end
  if type(a) ~= "table" or type(b) ~= "table" then return nil end
  local mta, mtb = getmetatable(a), getmetatable(b)
  if (mta and mta.__eq) or (mtb and mtb.__eq) then return nil end
  seen[a] = seen[a] or {}
  if seen[a][b] then return "" end  -- already being compared: cycles end here
  seen[a][b] = true
  for k, v in pairs(a) do
    local d = diff(v, b[k], seen)
    if d == nil then return "[" .. show(k) .. "]" end
    if d ~= "" then return "[" .. show(k) .. "]" .. d end
  end
  for k in pairs(b) do
    if a[k] == nil then return "[" .. show(k) .. "]" end
  end
  return ""
end

-- actual == expected; tables are compared element by element
function expect.eq(actual, expected, msg)
  count()
  local d = diff(actual, expected, {})
  if d ~= "" then
    local at = d and " (differs at " .. d .. ")" or ""
    fail(fmt("expected %s, got %s%s", show(expected), show(actual), at), msg)
  end
end

function expect.truthy(v, msg)
  count()
  if not v then fail("expected a true value, got " .. show(v), msg) end
end

function expect.falsy(v, msg)
  count()
  if v then fail("expected false or nil, got " .. show(v), msg) end
end

local function comparable(a, b)
  local ta, tb = type(a), type(b)
  return (ta == "number" and tb == "number") or (ta == "string" and tb == "string")
end

function expect.lt(a, b, msg)
  count()
  if not comparable(a, b) or not (a < b) then fail(fmt("expected %s < %s", show(a), show(b)), msg) end
end

function expect.le(a, b, msg)
  count()
  if not comparable(a, b) or not (a <= b) then fail(fmt("expected %s <= %s", show(a), show(b)), msg) end
end

function expect.gt(a, b, msg)
  count()
  if not comparable(a, b) or not (a > b) then fail(fmt("expected %s > %s", show(a), show(b)), msg) end
end

function expect.ge(a, b, msg)
  count()
  if not comparable(a, b) or not (a >= b) then fail(fmt("expected %s >= %s", show(a), show(b)), msg) end
end

-- fn must raise; with a pattern, the message must contain it, either literally (plain
-- find) or as a Lua pattern. Returns the error value.
function expect.error(fn, pattern, msg)
  count()
  if type(fn) ~= "function" and not (getmetatable(fn) or {}).__call then
    error("bad argument to 'expect.error': function expected, got " .. type(fn), 2)
  end
  local saved, saved_first = M._last_failure, M._first_failure
  local ok, err = pcall(fn)
  -- an expectation failing inside fn was expected here (tests of expect itself)
  M._last_failure, M._first_failure = saved, saved_first
  if ok then
    fail("expected an error, but the function returned normally", msg)
  elseif pattern ~= nil then
    local s = tostring(err)
    local matched = find(s, pattern, 1, true)
    if not matched then
      local okp, r = pcall(find, s, pattern)
      matched = okp and r
    end
    if not matched then fail(fmt("expected an error matching %q, got %q", pattern, s), msg) end
  end
  return err
end

-- every argument a finite number (a trailing string is the message):
-- expect.finite(w:position(p))
function expect.finite(...)
  count()
  local n, msg = select("#", ...), nil
  if n > 1 and type(select(n, ...)) == "string" then n, msg = n - 1, select(n, ...) end
  if n == 0 then fail("expected a finite number, got nothing", msg) end
  for i = 1, n do
    local x = select(i, ...)
    if type(x) ~= "number" or x ~= x or x == huge or x == -huge then
      fail(fmt("expected a finite number%s, got %s", n > 1 and " (value " .. i .. ")" or "", show(x)), msg)
    end
  end
end

-- ---- cases ------------------------------------------------------------------------

local function test(name, fn)
  if type(name) ~= "string" then error("bad argument #1 to 'test' (string expected, got " .. type(name) .. ")", 2) end
  if type(fn) ~= "function" then error("bad argument #2 to 'test' (function expected, got " .. type(fn) .. ")", 2) end
  if M._running then error("test() called inside a test case; define cases at the top of the file", 2) end
  M.cases[#M.cases + 1] = { name = name, fn = fn }
end

M.test, M.expect, M.show = test, expect, show
return M
