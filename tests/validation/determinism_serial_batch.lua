-- determinism_serial_batch.lua: the colouring has 64 colours (one bit each in a
-- per-particle mask); constraints that find none free go to one last batch that
-- shares particles and must run serially, whatever the thread count. A star does
-- that: every spoke touches the movable hub, so the hub's 64 first spokes fill the
-- 64 colours and the other 1936 land in the serial batch. That batch is far past the
-- 512 constraints from which a batch is split across threads, so were it split, two
-- threads would read and write the hub at once and threads = 2 would differ from
-- threads = 1. Exact equality: no tolerance.

local SPOKES = 2000

local function star(threads, solver)
  local w = wobble.world{ threads = threads, solver = solver, substeps = 4, iterations = 2, gravity = {0, 0, 0} }
  local hub = w:particle{ pos = {0, 1, 0}, mass = 5 }
  -- spokes on a sphere (a golden-angle spiral), rest lengths off by up to 10% so that
  -- every constraint pulls or pushes the hub
  for i = 1, SPOKES do
    local y = 1 - 2 * (i - 0.5) / SPOKES
    local r, phi = math.sqrt(1 - y * y), i * 2.399963229728653
    local p = w:particle{ pos = {r * math.cos(phi), 1 + y, r * math.sin(phi)}, mass = 0.01 }
    w:distance(hub, p, { rest = 1 + 0.1 * math.sin(7 * i), compliance = 1e-6 })
  end
  return w, hub
end

local function run(threads, solver)
  local w, hub = star(threads, solver)
  local trace = {}
  w:run{ frames = 20, on_frame = function(w) trace[#trace + 1] = w:hash() end }
  return trace, w, hub
end

for _, solver in ipairs{ "gauss-seidel", "jacobi" } do
  test("a hub with " .. SPOKES .. " spokes: threads = 1 vs 2 bit-identical (" .. solver .. ")", function()
    local t1, w, hub = run(1, solver)
    local t2 = run(2, solver)
    -- the scene is what the test is about: 64 colours and the serial batch
    expect.eq(w:stats().colours, 65, "64 colours + the serial batch")
    expect.eq(t1, t2, "hash after every frame")
    -- and the hub was actually pushed around by its spokes (no gravity here)
    local x, y, z = w:position(hub)
    expect.gt(math.abs(x) + math.abs(z) + math.abs(y - 1), 0, "the hub moved off its start")
    expect.finite(x, y, z)
  end)
end
