-- sandbox_paths.lua: the path rules of DESIGN §4. Reads: the scene's folder, the
-- assets folders, the output folder. Writes: only the output folder; a relative
-- path is taken inside it. Writes aimed outside use paths that do not exist, so a
-- broken sandbox would still change nothing.

local NOWHERE = "/tmp/wobble-sandbox-never-created/x.txt"

test("reading /etc/passwd is refused with the rule", function()
  local msg = "reading /etc/passwd is outside the allowed folders (scene, assets, out); use --unsafe"
  expect.error(function() io.open("/etc/passwd") end, msg)
  expect.error(function() io.open("/etc/passwd", "rb") end, msg)
  expect.error(function() io.lines("/etc/passwd") end, msg)
  expect.error(function() io.input("/etc/passwd") end, msg)
  expect.error(function() dofile("/etc/passwd") end, msg)
  expect.error(function() loadfile("/etc/passwd") end, msg)
end)

test("the error names the line that asked", function()
  expect.error(function()
    io.open("/etc/passwd") -- line 20
  end, "sandbox_paths.lua:20: reading /etc/passwd")
end)

test("'..' cannot climb out of the scene folder", function()
  local up = string.rep("../", 40) .. "etc/passwd"
  expect.error(function() io.open(up) end, "(/etc/passwd) is outside the allowed folders")
  -- a sibling folder of the scene's is outside it too
  expect.error(function() io.open("../cli/run.sh") end, "is outside the allowed folders")
  expect.error(function() io.open("./../../Makefile") end, "is outside the allowed folders")
end)

test("writing outside the output folder is refused", function()
  expect.error(function() io.open(NOWHERE, "w") end,
               "writing " .. NOWHERE .. " is outside the output folder")
  for _, mode in ipairs{ "w", "a", "r+", "w+", "a+", "wb" } do
    expect.error(function() io.open(NOWHERE, mode) end, "is outside the output folder", mode)
  end
  expect.error(function() io.output(NOWHERE) end, "is outside the output folder")
  expect.error(function() os.remove(NOWHERE) end, "is outside the output folder")
  expect.error(function() os.rename("sandbox_never.txt", NOWHERE) end, "is outside the output folder")
  -- not even the scene's own folder
  expect.error(function() io.open("/etc/wobble-never-created.txt", "w") end, "is outside the output folder")
end)

test("'..' cannot climb out of the output folder", function()
  expect.error(function() io.open("../wobble-escape-never.txt", "w") end, "is outside the output folder")
  expect.error(function() io.open("a/../../wobble-escape-never.txt", "w") end, "is outside the output folder")
  expect.error(function() io.open("not/yet/../../../x", "w") end, "is outside the output folder")
end)

test("a relative write lands in the output folder and reads back", function()
  local f = assert(io.open("sandbox_paths/deep/er/hello.txt", "w"))
  f:write("hello from the sandbox\n")
  f:close()
  -- the read finds it in the output folder (not here, not in the scene's folder)
  local g = assert(io.open("sandbox_paths/deep/er/hello.txt"))
  expect.eq(g:read("l"), "hello from the sandbox")
  g:close()
  local lines = 0
  for _ in io.lines("sandbox_paths/deep/er/hello.txt") do lines = lines + 1 end
  expect.eq(lines, 1)
  expect.truthy(os.rename("sandbox_paths/deep/er/hello.txt", "sandbox_paths/moved.txt"))
  expect.truthy(os.remove("sandbox_paths/moved.txt"))
  expect.eq(io.open("sandbox_paths/moved.txt"), nil, "removed")
end)

test("a Lua file written to the output folder can be loaded as text", function()
  local f = assert(io.open("sandbox_paths/module.lua", "w"))
  f:write("#!/usr/bin/env wobble\nreturn 6 * 7\n")
  f:close()
  expect.eq(dofile("sandbox_paths/module.lua"), 42)
  expect.eq(loadfile("sandbox_paths/module.lua")(), 42)
  local env = { x = 3 }
  f = assert(io.open("sandbox_paths/env.lua", "w"))
  f:write("return x\n")
  f:close()
  expect.eq(loadfile("sandbox_paths/env.lua", "bt", env)(), 3)
end)

test("the scene's own folder is readable", function()
  local f = assert(io.open("sandbox_paths.lua"))
  expect.eq(f:read("l"), "-- sandbox_paths.lua: the path rules of DESIGN §4. Reads: the scene's folder, the")
  f:close()
  expect.eq(type(loadfile("sandbox_functions.lua")), "function")
end)

test("a missing file is nil, message (not a sandbox error)", function()
  local f, err = io.open("sandbox_no_such_file.txt")
  expect.eq(f, nil)
  expect.truthy(err:find("No such file", 1, true), err)
  local g, err2 = loadfile("sandbox_no_such_file.lua")
  expect.eq(g, nil)
  expect.truthy(err2:find("cannot open", 1, true), err2)
end)
