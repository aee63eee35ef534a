-- cloth_heap.lua: a cloth dropped onto the floor folds into a heap on itself without
-- passing through (self-collision). A 0.8 x 2 m sheet hangs straight down, its
-- lower edge just above the floor, rippled and swirling a little; let go, its lower part
-- buckles on the floor and the rest falls onto it in folds. It is one body built with
-- self_collide = true: its particles collide with each other except for the rest
-- neighbours (linked, or closer than r_i + r_j as built). Soft in bending (skip-one
-- bend_links of compliance 10 m/N) so it folds tightly; air drag (world damping 0.5 /s)
-- lets it settle in a few seconds. (Written when w:cloth's `bend` meant those links; the
-- dihedral `bend = 10` rad/(N m) is far stiffer: springy folds that never came to rest.)
-- Try --set self_collide=0 or --set contacts=0 to watch the folds pass through each other.
-- Run: build/wobble run scripts/cloth_heap.lua [--record out/heap/]
--      build/wobble test scripts/cloth_heap.lua   (runs it and checks the heap)
-- Options: --set seconds=4, --set bend_links=10, --set bend=1000 (dihedral bends too),
--          --set res=16 (particles across; 40 down)
local args = wobble.args
local w = wobble.world{ substeps = 20, iterations = 2, damping = args.damping or 0.5, contacts = args.contacts ~= 0 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.8 }
local width, size = args.width or 0.8, args.height or 2 -- m
local nx = args.res or 16
local n = math.floor(nx * size / width + 0.5)
local cloth = w:cloth{ origin = {-width / 2, 0, 0}, size = {width, size}, res = {nx, n}, mass = 0.3, compliance = 1e-6,
                       bend_links = args.bend_links or 10, bend = args.bend,
                       self_collide = args.self_collide ~= 0, friction = args.friction or 0.8 }
-- hang the sheet straight down in the x-y plane, its lower edge a little above the
-- floor, rippled so that it buckles as it lands, with a slow swirl; let go, it falls
-- onto its own lower part in folds
local drop = args.drop or 0.05
local r = w:radius(cloth.particles[1])
local built = {} -- the flat sheet as built: the rule for rest neighbours uses it
for _, p in ipairs(cloth.particles) do
  local u, _, v = w:position(p)
  built[p] = { u, v }
  local x, y = u, v + drop
  w:set_position(p, x, y, 0.03 * math.sin(2 * math.pi * v / (args.wave or 0.3) + 2 * x))
  w:set_velocity(p, -0.4 * x * v, 0, 0.3 * math.sin(2 * math.pi * v / (args.swirl or 0.7) + 1.5 * x))
end

local seconds = args.seconds or 4
w:run{ seconds = math.max(seconds - 1, 0) }
-- at rest: how far any particle still moves in the last second
local before = {}
for _, p in ipairs(cloth.particles) do before[p] = { w:position(p) } end
w:run{ seconds = 1 }
local moved = 0
for _, p in ipairs(cloth.particles) do
  local x, y, z = w:position(p)
  local b = before[p]
  moved = math.max(moved, math.sqrt((x - b[1]) ^ 2 + (y - b[2]) ^ 2 + (z - b[3]) ^ 2))
end

-- the self-collision rule's pairs (docs/physics.md, "Rest neighbours never touch"): not
-- joined by a link, and at least pi/2 (r_i + r_j) = pi r apart as built (a pair made
-- closer is joined along the links within sqrt 2 pi r here: the corners across each
-- square's unlinked diagonal); of them, the closest now (over its contact distance 2 r)
-- and how many lie within 1.5 x 2 r (a fold lying on another: without folds, none)
local linked = {}
for _, c in ipairs(w:distances()) do
  local a, b = c:particles()
  linked[a * 100000 + b], linked[b * 100000 + a] = true, true
end
local worst, stacked = math.huge, 0
for i, p in ipairs(cloth.particles) do
  local px, py, pz = w:position(p)
  for k = i + 1, #cloth.particles do
    local q = cloth.particles[k]
    local bp, bq = built[p], built[q]
    if not linked[p * 100000 + q] and math.sqrt((bp[1] - bq[1]) ^ 2 + (bp[2] - bq[2]) ^ 2) >= math.pi * r then
      local qx, qy, qz = w:position(q)
      local d = math.sqrt((px - qx) ^ 2 + (py - qy) ^ 2 + (pz - qz) ^ 2) / (2 * r)
      worst = math.min(worst, d)
      if d < 1.5 then stacked = stacked + 1 end
    end
  end
end
local lowest, highest, fastest = math.huge, -math.huge, 0
for _, p in ipairs(cloth.particles) do
  local _, y = w:position(p)
  local vx, vy, vz = w:velocity(p)
  lowest, highest = math.min(lowest, y), math.max(highest, y)
  fastest = math.max(fastest, math.sqrt(vx * vx + vy * vy + vz * vz))
end
print(string.format("cloth heap: %d particles (r = %.3f m), %.3f to %.3f m above the floor, fastest %.3f m/s, " ..
                    "moved at most %.3f m in the last second; " ..
                    "closest non-neighbours %.3f of 2 r, %d pairs of folds lying on each other; %d contacts",
                    #cloth.particles, r, lowest, highest, fastest, moved, worst, stacked, w:stats().particle_contacts))

if test then  -- under `wobble test`: the header's claim
  test("the cloth lies in a heap of folds on the floor without passing through itself", function()
    -- the floor and the links move particles after the contact pass of a substep;
    -- 10% of the contact distance covers that (as in tests/validation/contacts.lua)
    expect.ge(worst, 0.9, "no two non-neighbour particles closer than 0.9 x their contact distance")
    expect.gt(stacked, 50, "folds lie on each other")
    expect.gt(highest, 4 * r, "a heap: higher than a layer or two on the floor")
    expect.gt(lowest, 0.9 * r, "on the floor, not through it")
    expect.lt(highest, 0.5 * size, "fallen: not standing")
    -- settled: what still moves is a jitter of a few cm/s where folds press on each
    -- other (measured: 1 cm in the last second, 0.07 m/s at most), not a fold sliding
    expect.lt(moved, 0.03, "no particle moved more than 3 cm in the last second")
    expect.lt(fastest, 0.2, "no particle faster than 0.2 m/s")
  end)
end
