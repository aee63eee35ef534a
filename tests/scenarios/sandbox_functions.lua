-- sandbox_functions.lua: what the sandbox takes away (DESIGN §4) and what it keeps.
-- Run by `wobble test` without --unsafe.

test("no process control", function()
  -- refused functions raise a message that names them and the way out
  expect.error(function() os.execute("ls") end, "os.execute is not available in the sandbox (--unsafe allows it)")
  expect.error(function() io.popen("ls") end, "io.popen is not available in the sandbox")
  expect.error(function() os.tmpname() end, "os.tmpname is not available in the sandbox")
  -- io.tmpfile writes a file in /tmp, outside the output folder
  expect.error(function() io.tmpfile() end, "io.tmpfile is not available in the sandbox (--unsafe allows it)")
  expect.error(function() os.setlocale("C") end, "os.setlocale is not available in the sandbox")
  expect.error(function() os.exit(0) end, "os.exit is not available in the sandbox")
  expect.error(function() os.exit(true, true) end, "os.exit is not available")
end)

test("no C code and no bytecode producers", function()
  expect.error(function() package.loadlib("libc.so.6", "puts") end, "package.loadlib is not available")
  expect.eq(package.cpath, "")
  expect.eq(#package.searchers, 2, "preload and Lua files only")
  expect.error(function() string.dump(print) end, "string.dump is not available")
  expect.error(function() ("").dump(print) end, "string.dump is not available")
end)

test("no debug library, not even through require", function()
  expect.eq(debug, nil)
  expect.eq(package.loaded.debug, nil)
  expect.error(function() require "debug" end, "module 'debug' not found")
end)

test("the harmless libraries are all there", function()
  for _, name in ipairs{ "string", "table", "math", "utf8", "coroutine", "io", "os", "package" } do
    expect.eq(type(_G[name]), "table", name)
  end
  expect.eq(type(os.clock), "function")
  expect.eq(type(os.time), "function")
  expect.eq(type(os.getenv("HOME") or ""), "string", "os.getenv reads the environment")
  expect.eq(type(io.write), "function")
  expect.eq(type(require), "function")
end)

-- a Lua 5.4 binary chunk starts with ESC "Lua" 0x54
local BYTECODE = "\27Lua\x54\0\x19\x93\r\n\x1a\n\4\8\8"

test("load refuses bytecode whatever the mode", function()
  local f, err = load(BYTECODE)
  expect.eq(f, nil)
  expect.error(function() error(err) end, "attempt to load a binary chunk")
  for _, mode in ipairs{ "b", "bt", "t" } do
    f, err = load(BYTECODE, "x", mode)
    expect.eq(f, nil, mode)
    expect.truthy(err:find("binary chunk", 1, true), mode)
  end
  -- a reader function cannot sneak it in either
  local sent = false
  f = load(function() if not sent then sent = true; return BYTECODE end end)
  expect.eq(f, nil)
end)

test("load still loads text, with or without an environment", function()
  expect.eq(load("return 1 + 2")(), 3)
  expect.eq(load("return 1 + 2", "chunk", "b")(), 3, "mode b is read as t")
  expect.eq(load("return x", "chunk", "t", { x = 5 })(), 5)
  -- an explicit nil environment stays nil (not _G)
  expect.error(load("return print", "nil_env", "t", nil), "attempt to index a nil value")
  local parts, i = { "return ", "4", "2" }, 0
  expect.eq(load(function() i = i + 1; return parts[i] end)(), 42)
end)

test("package.path cannot be pointed outside the allowed folders", function()
  local saved = package.path
  package.path = "/etc/?"
  local ok, err = pcall(require, "passwd")
  package.path = saved
  expect.falsy(ok)
  expect.truthy(tostring(err):find("module 'passwd' not found", 1, true), tostring(err))
end)

test("require finds the library's Lua modules", function()
  local T = require "wobble.test"
  expect.eq(T.test, test)
  expect.eq(T.expect, expect)
  expect.eq(require "wobble", wobble)
end)

test("deep recursion is Lua's stack overflow error, not a crash", function()
  local function deeper(n) return 1 + deeper(n + 1) end
  expect.error(function() return deeper(1) end, "stack overflow")
  -- through C boundaries (metamethods, pcall): the C stack limit
  local t = setmetatable({}, {})
  getmetatable(t).__index = function(self, k) return self[k] end
  expect.error(function() return t.x end, "stack overflow")
  local function nest() local ok, err = pcall(nest); error(err, 0) end
  expect.error(nest, "stack overflow")
  -- and the state is fine afterwards
  expect.eq(select("#", table.unpack({ 1, 2, 3 })), 3)
end)
