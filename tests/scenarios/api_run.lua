-- api_run.lua: w:run{frames | seconds, on_frame} and w:step.

local function falling()
  local w = wobble.world{ dt = 1 / 60 }
  w:particle{ pos = {0, 10, 0} }
  return w
end

test("run frames", function()
  local w = falling()
  expect.eq(w:run{ frames = 10 }, 10)
  expect.eq(w:frame(), 10)
  expect.near(w:time(), 10 / 60, 1e-12)
  expect.eq(w:run{ frames = 0 }, 0)
  expect.eq(w:frame(), 10)
end)

test("run seconds rounds to whole frames", function()
  local w = falling()
  expect.eq(w:run{ seconds = 0.5 }, 30)
  expect.eq(w:run{ seconds = 0.51 }, 31)  -- 30.6 frames
  expect.eq(w:run{ seconds = 0.001 }, 0)
  expect.eq(w:frame(), 61)
end)

test("on_frame gets the world, its frame counter and its time", function()
  local w = falling()
  w:step(); w:step()
  local frames, times = {}, {}
  w:run{ frames = 3, on_frame = function(ww, frame, t)
    expect.eq(ww, w)
    frames[#frames + 1] = frame
    times[#times + 1] = t
    expect.eq(frame, w:frame())
  end }
  expect.eq(#frames, 3)
  expect.eq(frames[1], 3); expect.eq(frames[3], 5)
  expect.eq(math.type(frames[1]), "integer")
  expect.near(times[3], 5 / 60, 1e-12)
end)

test("on_frame returning false stops the run", function()
  local w = falling()
  local n = w:run{ frames = 100, on_frame = function(_, frame) return frame < 7 end }
  expect.eq(n, 7)
  expect.eq(w:frame(), 7)
  -- nil (no return value) keeps going
  expect.eq(w:run{ frames = 5, on_frame = function() end }, 5)
end)

test("a callable table is a valid on_frame", function()
  local w = falling()
  local calls = 0
  local cb = setmetatable({}, { __call = function() calls = calls + 1 end })
  w:run{ frames = 4, on_frame = cb }
  expect.eq(calls, 4)
end)

test("an error in on_frame propagates with its file:line", function()
  local w = falling()
  local ok, err = pcall(function()
    w:run{ frames = 10, on_frame = function(_, frame)
      if frame == 3 then error("boom at three") end
    end }
  end)
  expect.falsy(ok)
  expect.truthy(tostring(err):find("api_run%.lua:%d+: boom at three"), tostring(err))
  expect.eq(w:frame(), 3)
  -- the world and w:run still work afterwards
  expect.eq(w:run{ frames = 2 }, 2)
  -- non-string error values pass through untouched
  local obj = {}
  local ok2, err2 = pcall(w.run, w, { frames = 1, on_frame = function() error(obj) end })
  expect.falsy(ok2)
  expect.eq(err2, obj)
end)

test("on_frame may close the world: the run stops with an error", function()
  local w = falling()
  local ok, err = pcall(w.run, w, { frames = 5, on_frame = function(ww) ww:close() end })
  expect.falsy(ok)
  expect.truthy(tostring(err):find("closed world"), tostring(err))
end)

test("run and step give the same state", function()
  local a, b = falling(), falling()
  a:run{ frames = 12 }
  for _ = 1, 12 do b:step() end
  expect.eq(a:hash(), b:hash())
end)

test("a cloth falls onto a sphere and stays above it", function()
  local w = wobble.world{ substeps = 10 }
  local b = w:cloth{ origin = {-1, 1, -1}, size = {2, 2}, res = {12, 12}, radius = 0.02 }
  local s = w:collider{ shape = "sphere", center = {0, 0, 0}, radius = 0.5 }
  w:run{ seconds = 1 }
  local inside = 0
  for _, id in ipairs(b.particles) do
    if s:distance(w:position(id)) < 0 then inside = inside + 1 end
  end
  expect.eq(inside, 0)
  expect.truthy(w:stats().contacts > 0, "touching the sphere")
end)

test("on_frame may yield: a run can be driven from a coroutine", function()
  local w = falling()
  local co = coroutine.wrap(function()
    return w:run{ frames = 3, on_frame = function(_, frame) coroutine.yield(frame) end }
  end)
  expect.eq(co(), 1)
  expect.eq(w:frame(), 1)
  expect.eq(co(), 2)
  expect.eq(co(), 3)
  expect.eq(co(), 3) -- the run's result: frames stepped
end)
