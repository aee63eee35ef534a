-- determinism_tets.lua: volume constraints and Neo-Hookean tets are projected in colour
-- batches (no two of a batch share a movable particle), a batch split across threads
-- (DESIGN §2): the same scene gives bit-identical states with 1, 2 and 3 threads.
-- Exact equality of w:hash() (an FNV-1a hash of the whole state), no tolerance.

-- a 10x10x10-cell block (6000 tets: batches of several hundred, split across threads)
-- dropped on the ground and pressed by a box
local function block(threads, neo)
  local w = wobble.world{ threads = threads, substeps = 6, iterations = 2 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
  local box = w:collider{ shape = "box", center = {0, 1.45, 0}, half = {0.3, 0.1, 0.3} }
  box:set_velocity(0, -0.4, 0)
  local opts = { min = {-0.5, 0.2, -0.5}, max = {0.5, 1.2, 0.5}, res = {11, 11, 11}, mass = 20,
                 tets = true, friction = 0.4 }
  if neo then opts.young, opts.poisson = 2e4, 0.3
  else opts.volume_compliance, opts.compliance = 1e-7, 1e-4 end
  w:lattice(opts)
  return w
end

local function trace(w, frames)
  local t = {}
  w:run{ frames = frames, on_frame = function(w, f)
    if f % 5 == 0 then t[#t + 1] = w:hash() end
  end }
  return t
end

for _, kind in ipairs{ "volume", "tet" } do
  test("a " .. kind .. " block: threads 1, 2, 3 give identical hashes", function()
    local w1 = block(1, kind == "tet")
    local t1 = trace(w1, 30)
    expect.eq(trace(block(2, kind == "tet"), 30), t1, "threads = 2")
    expect.eq(trace(block(3, kind == "tet"), 30), t1, "threads = 3")
    -- the block did something: it fell and the box pressed it
    local _, y = w1:position(1)
    expect.lt(y, 0.2, "the block's corner fell")
    expect.eq(w1:warnings(), 0, "no warnings")
  end)
end

-- a hub shared by 2000 tets: 64 colours take 64 of them and the rest go to one last
-- batch that shares the hub and must stay serial; split, two threads would write the hub
-- at once and threads = 2 would differ from threads = 1
local N = 2000
local function star(threads, neo)
  local w = wobble.world{ threads = threads, substeps = 4, iterations = 2, gravity = {0, 0, 0} }
  local hub = w:particle{ pos = {0, 1, 0}, mass = 5 }
  local ps = {}
  for i = 1, N do
    local y = 1 - 2 * (i - 0.5) / N
    local r, phi = math.sqrt(1 - y * y), i * 2.399963229728653
    local c = {r * math.cos(phi), 1 + y, r * math.sin(phi)}
    local a = w:particle{ pos = c, mass = 0.01 }
    local b = w:particle{ pos = {c[1] + 0.05, c[2], c[3]}, mass = 0.01 }
    local d = w:particle{ pos = {c[1], c[2] + 0.05, c[3] + 0.03}, mass = 0.01 }
    if neo then w:tet(hub, a, b, d, { young = 0.1, poisson = 0.3 })
    else w:volume(hub, a, b, d, { compliance = 1e-6 }) end
    ps[#ps + 1] = a
  end
  -- push every spike's tip in or out, so that every tet pulls or pushes the hub
  for i, a in ipairs(ps) do
    local x, y, z = w:position(a)
    local s = 1 + 0.1 * math.sin(7 * i)
    w:set_position(a, x * s, 1 + (y - 1) * s, z * s)
  end
  return w, hub
end

for _, kind in ipairs{ "volume", "tet" } do
  test("a hub in " .. N .. " " .. kind .. "s (the serial batch): threads 1 vs 2 bit-identical", function()
    local w1, hub = star(1, kind == "tet")
    local t1 = trace(w1, 20)
    expect.eq(trace(star(2, kind == "tet"), 20), t1, "threads = 2")
    local x, y, z = w1:position(hub)
    expect.gt(math.abs(x) + math.abs(z) + math.abs(y - 1), 0, "the hub moved off its start")
    expect.finite(x, y, z)
  end)
end
