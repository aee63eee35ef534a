-- sandbox_escapes.lua: ways around the file rules of DESIGN §4 that the plain path
-- tests (sandbox_paths.lua) do not try: names that are not strings, names with a zero
-- byte, precompiled chunks in files, and media files that make ffmpeg open others.
-- What needs a separate process (files created in the current folder, --unsafe, a
-- real binary chunk) is in tests/cli/sandbox.sh.

local D = "sandbox_escapes/"   -- in the output folder

local function write(name, bytes)
  local f = assert(io.open(D .. name, "wb"))
  f:write(bytes)
  f:close()
end

test("a number is not a file name: refused before the io library turns it into one", function()
  local named = "file name (a string) expected, got number"
  expect.error(function() io.output(4242) end, "bad argument #1 to 'output' (file name or file handle expected, got number)")
  expect.error(function() io.input(4242) end, "bad argument #1 to 'input' (file name or file handle expected, got number)")
  expect.error(function() io.lines(4242) end, "bad argument #1 to 'lines' (" .. named)
  expect.error(function() io.open(4242) end, "bad argument #1 to 'open' (" .. named)
  expect.error(function() io.open(4242, "w") end, "bad argument #1 to 'open' (" .. named)
  expect.error(function() os.remove(4242) end, "bad argument #1 to 'remove' (" .. named)
  expect.error(function() os.rename(4242, D .. "x") end, "bad argument #1 to 'rename' (" .. named)
  expect.error(function() os.rename(D .. "x", 4242) end, "bad argument #2 to 'rename' (" .. named)
  expect.error(function() loadfile(4242) end, "bad argument #1 to 'loadfile' (" .. named)
  expect.error(function() dofile(4242) end, "bad argument #1 to 'dofile' (" .. named)
  expect.error(function() io.output(true) end, "(file name or file handle expected, got boolean)")
  expect.error(function() io.input({}) end, "(file name or file handle expected, got table)")
  expect.eq(io.open("4242"), nil, "nothing called 4242 was made, here or in the output folder")
end)

test("wobble's own functions take a file name only as a string, without a zero byte", function()
  local w = wobble.world{}
  local b = w:rope{ from = {0, 1, 0}, to = {1, 1, 0}, segments = 2 }
  local m = wobble.mesh{ vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, triangles = {{1, 2, 3}} }
  local s = w:skin(m, b, { bones = 1, neighbours = 2 })
  local r = wobble.renderer{ width = 16, height = 16, backend = "null" }
  r:draw(w)
  local calls = {
    { "save", function(x) return w:save(x) end },
    { "load", function(x) return wobble.load(x) end },
    { "load_particles", function(x) return w:load_particles(x) end },
    { "load_mesh", function(x) return wobble.load_mesh(x) end },
    { "save_obj", function(x) return m:save_obj(x) end },
    { "save_obj", function(x) return s:save_obj(x) end },
    { "record_pc2", function(x) return w:record_pc2(x) end },
    { "record_pc2", function(x) return s:record_pc2(x) end },
    { "record_vtk", function(x) return w:record_vtk(x) end },
    { "save_vtp", function(x) return w:save_vtp(x) end },
    { "save_png", function(x) return r:save_png(x) end },
    { "record", function(x) return r:record(x) end },
    { "read_png", function(x) return wobble.read_png(x) end },
    { "probe", function(x) return wobble.probe(x) end },
    { "read_frame", function(x) return wobble.read_frame(x) end },
  }
  for _, c in ipairs(calls) do
    local name, f = c[1], c[2]
    expect.error(function() f(4242) end, "to '" .. name .. "' (file name (a string) expected, got number)")
    expect.error(function() f("x.json\0.png") end, "to '" .. name .. "' (file name contains a zero byte)")
  end
  expect.eq(io.open("4242"), nil, "nothing called 4242 was made in the output folder")
end)

test("io.read after a refused io.input(4242) still reads the input it had", function()
  local before = io.input()
  expect.error(function() io.input(4242) end, "got number")
  expect.eq(io.input(), before)
  expect.error(function() io.output(4.5) end, "got number")
  expect.eq(io.output(), io.stdout)
end)

test("io.input / io.output still take file handles and names", function()
  expect.eq(io.output(io.stdout), io.stdout)
  local out = io.output(D .. "default.txt")     -- a name: in the output folder
  io.write("through io.write\n")
  io.close(out)
  io.output(io.stdout)
  local f = assert(io.open(D .. "default.txt"))
  expect.eq(io.input(f), f, "an open handle is taken as it is")
  expect.eq(io.read("l"), "through io.write")
  io.input(io.stdin)
  f:close()
  io.input(D .. "default.txt")
  expect.eq(io.read("l"), "through io.write")
  io.input():close()
  io.input(io.stdin)
  expect.error(function() io.input("/etc/passwd") end, "outside the allowed folders")
  expect.error(function() io.output("/tmp/wobble-never-created.txt") end, "outside the output folder")
end)

test("a zero byte in a file name is refused, not cut short", function()
  local msg = "file name contains a zero byte"
  expect.error(function() io.open(D .. "ok.txt\0/../../../../../../etc/passwd") end, msg)
  expect.error(function() io.open(D .. "ok.txt\0.lua", "w") end, msg)
  expect.error(function() io.lines(D .. "ok.txt\0x") end, msg)
  expect.error(function() io.input(D .. "ok.txt\0x") end, msg)
  expect.error(function() io.output(D .. "ok.txt\0x") end, msg)
  expect.error(function() os.remove(D .. "ok.txt\0x") end, msg)
  expect.error(function() os.rename(D .. "a\0b", D .. "c") end, msg)
  expect.error(function() loadfile(D .. "ok.lua\0x") end, msg)
  expect.error(function() dofile(D .. "ok.lua\0x") end, msg)
  expect.eq(io.open(D .. "ok.txt"), nil, "nothing was written")
end)

test("file:lines reads only its own file", function()
  write("lines.txt", "a\nb\n")
  local f = assert(io.open(D .. "lines.txt"))
  local got = {}
  for l in f:lines("l") do got[#got + 1] = l end
  f:close()
  expect.eq(table.concat(got, ","), "a,b")
  expect.error(function() f:lines() end, "closed file")
end)

test("a precompiled chunk in a file is refused by loadfile and dofile", function()
  -- the header of a Lua 5.4 binary chunk; the sandbox refuses it before parsing more
  local bin = "\27LuaT\0\25\147\13\10\26\10\4\8\8"
  local msg = "precompiled (binary) chunk, not allowed in the sandbox (--unsafe allows it)"
  write("chunk.luac", bin .. string.rep("\0", 32))
  write("chunk_shebang.lua", "#!/usr/bin/env wobble\n" .. bin .. string.rep("\0", 32))
  for _, name in ipairs{ "chunk.luac", "chunk_shebang.lua" } do
    local f, err = loadfile(D .. name)
    expect.eq(f, nil, name)
    expect.truthy(err:find(msg, 1, true), err)
    expect.truthy(err:find(name, 1, true), "the message names the file: " .. err)
    expect.error(function() dofile(D .. name) end, msg)
    expect.eq(loadfile(D .. name, "b"), nil, "mode 'b' does not let it through")
  end
  expect.error(function() assert(load(bin)) end, "attempt to load a binary chunk")
end)

test("loadfile keeps the mode it is given: 'b' loads no text", function()
  write("text.lua", "return 1\n")
  local f, err = loadfile(D .. "text.lua", "b")
  expect.eq(f, nil)
  expect.truthy(err:find("attempt to load a text chunk (mode is 'b')", 1, true), err)
  expect.eq(loadfile(D .. "text.lua", "t")(), 1)
end)

test("package.searchpath cannot tell whether a file exists outside the allowed folders", function()
  local f, err = package.searchpath("passwd", "/etc/?")
  expect.eq(f, nil)
  expect.eq(err, "no file '/etc/passwd'", "the same answer as for a file that is not there")
  expect.eq(select(2, package.searchpath("etc.passwd", "/?")), "no file '/etc/passwd'")
  expect.eq(select(2, package.searchpath("no-such-file", "/etc/?")), "no file '/etc/no-such-file'")
  -- the library folder is still searched
  expect.truthy(package.searchpath("wobble.test", package.path):match("wobble/test%.lua$"))
end)

-- ---- media: ffmpeg / ffprobe read the one file named, nothing it names

local r = wobble.renderer{ width = 16, height = 16, backend = "null" }
local function record(name, n)
  r:record(D .. name)
  local w = wobble.world{}
  for _ = 1, n do r:draw(w) end
  r:stop()
end

test("a plain mp4, gif and png still read", function()
  record("clip.mp4", 3)
  record("clip.gif", 2)
  r:save_png(D .. "frame.png")
  for _, name in ipairs{ "clip.mp4", "clip.gif", "frame.png" } do
    local w, h = wobble.read_frame(D .. name)
    expect.eq(w, 16, name); expect.eq(h, 16, name)
    expect.eq(assert(wobble.probe(D .. name)).width, 16, name)
  end
  expect.eq(wobble.probe(D .. "clip.mp4").frames, 3)
end)

test("a playlist or list naming another file is refused, whatever its name", function()
  local msg = "is not a media file wobble reads"
  -- HLS: ffmpeg would play clip.mp4 (or any file on the machine) through it
  write("hls.mp4", "#EXTM3U\n#EXT-X-TARGETDURATION:1\n#EXTINF:1,\nclip.mp4\n#EXT-X-ENDLIST\n")
  write("hls.m3u8", "#EXTM3U\n#EXT-X-TARGETDURATION:1\n#EXTINF:1,\nclip.mp4\n#EXT-X-ENDLIST\n")
  write("list.png", "ffconcat version 1.0\nfile clip.mp4\n")
  write("list.gif", "ffconcat version 1.0\nfile clip.mp4\n")
  write("dash.mp4", '<?xml version="1.0"?>\n<MPD xmlns="urn:mpeg:dash:schema:mpd:2011"></MPD>\n')
  for _, case in ipairs{ { "hls.mp4", "(an HLS playlist)" }, { "hls.m3u8", "(an HLS playlist)" },
                         { "list.png", "(an ffconcat list)" }, { "list.gif", "(an ffconcat list)" },
                         { "dash.mp4", "(XML: a DASH manifest" } } do
    local name, what = case[1], case[2]
    local w, err = wobble.read_frame(D .. name)
    expect.eq(w, nil, name)
    expect.truthy(err:find(name .. " " .. msg .. " " .. what, 1, true), err)
    if not name:match("%.png$") then   -- probe reads a .png itself (no ffprobe)
      local p, perr = wobble.probe(D .. name)
      expect.eq(p, nil, name)
      expect.truthy(perr:find(msg .. " " .. what, 1, true), perr)
    end
  end
end)

test("a folder is not a video", function()
  local w, err = wobble.read_frame("sandbox_escapes")
  expect.eq(w, nil)
  expect.truthy(err:find("cannot read .*sandbox_escapes: Is a directory"), err)
  expect.eq(wobble.probe("sandbox_escapes"), nil)
end)

test("protocols in a name are only a name", function()
  record("concat:clip.mp4", 2)  -- a file of that name: read as the file it is
  expect.eq(wobble.read_frame(D .. "concat:clip.mp4"), 16)
  expect.eq(wobble.probe(D .. "concat:clip.mp4").frames, 2)
  for _, name in ipairs{ "subfile:,,start,0,end,0,,:" .. D .. "clip.mp4", "concat:" .. D .. "clip.mp4|" .. D .. "clip.mp4" } do
    local w, err = wobble.read_frame(name)
    expect.eq(w, nil, name)
    expect.truthy(err:find("cannot read", 1, true), err)
    expect.eq(wobble.probe(name), nil, name)
  end
end)
