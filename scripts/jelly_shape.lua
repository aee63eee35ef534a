-- jelly_shape.lua: three jelly cubes dropped onto the floor, held together by shape
-- matching (w:shape_match, Müller et al. 2005) instead of stiff links: each cube's links
-- are very soft, and one cluster over all its particles pulls them towards the rest
-- shape, turned and moved with the cube. Left: stiffness 1, a rigid block that lands
-- without a dent (it lands on an edge and tips flat a few cm outwards, as a rigid body of
-- its shape does: tests/validation/shape_match.lua). Middle: stiffness 0.4, a jelly that squashes on impact and springs back.
-- Right: stiffness 0.4 with yield = 0.04, a plastic one that keeps the dent of its
-- landing (its rest shape flows towards the squashed one past a strain of 0.04).
-- Try --set stiffness=0.2 for a softer jelly in the middle (it sags by a tenth of its
-- height under its own weight: the cluster pulls with about s / (1 - s) x 3600 / s^2).
-- Run: build/wobble run scripts/jelly_shape.lua [--record out/jelly/] (the three side by side)
local args = wobble.args
local w = wobble.world{ substeps = 10, damping = 0.5 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.6 }

local H = 0.5 -- the cubes' side (m)
local function cube(x, opts, tilt)
  -- tilted a little, so it lands on an edge and has to turn
  local b = w:lattice{ min = {x - H / 2, 1.2, -H / 2}, max = {x + H / 2, 1.2 + H, H / 2}, res = {5, 5, 5}, mass = 2,
                       compliance = 1, friction = 0.6 }
  local c, s = math.cos(tilt), math.sin(tilt)
  for _, p in ipairs(b.particles) do
    local px, py, pz = w:position(p)
    local dx, dy = px - x, py - (1.2 + H / 2)
    w:set_position(p, x + c * dx - s * dy, 1.2 + H / 2 + s * dx + c * dy, pz)
  end
  return b, w:shape_match(b, opts)
end
-- 1.4 m apart, each tilted so that its landing moves it outwards: they never meet
local rigid, rs = cube(-1.4, { stiffness = 1 }, -0.3)
local jelly, js = cube(0, { stiffness = args.stiffness or 0.4 }, 0.3)
local dent, ds = cube(1.4, { stiffness = args.stiffness or 0.4, yield = 0.04, creep = 10 }, 0.3)

-- the camera `--record` draws with and `wobble view` starts with
wobble.camera{ eye = {0, 1.6, 4.6}, target = {0, 0.4, 0} }
local squash = 1 -- the jelly's lowest height / H while landing
local function height(b)
  local lo, hi = math.huge, -math.huge
  for _, p in ipairs(b.particles) do
    local _, y = w:position(p)
    lo, hi = math.min(lo, y), math.max(hi, y)
  end
  return hi - lo
end
local function xrange(b)
  local lo, hi = math.huge, -math.huge
  for _, p in ipairs(b.particles) do
    local x = w:position(p)
    lo, hi = math.min(lo, x), math.max(hi, x)
  end
  return lo, hi
end
local gap = math.huge -- the narrowest gap between neighbouring cubes (m)
w:run{ seconds = args.seconds or 4, on_frame = function(w)
  squash = math.min(squash, height(jelly) / H)
  local _, r1 = xrange(rigid)
  local j0, j1 = xrange(jelly)
  local d0 = xrange(dent)
  gap = math.min(gap, j0 - r1, d0 - j1)
end }

local hr, hj, hd = height(rigid) / H, height(jelly) / H, height(dent) / H
print(string.format("heights / side at the end: rigid %.3f, jelly %.3f (%.3f at its most squashed), plastic %.3f",
                    hr, hj, squash, hd))
print(string.format("strains: rigid %.4f, jelly %.4f, plastic %.4f; narrowest gap between cubes %.2f m",
                    rs:strain(), js:strain(), ds:strain(), gap))

if test then  -- under `wobble test`: the header's claim
  test("the rigid cube lands rigid, the jelly springs back, the plastic one keeps its dent", function()
    expect.near(hr, 1, 0.01, "the rigid cube keeps its height (within 1%)")
    expect.lt(squash, 0.8, "the jelly squashes on impact (measured 0.72 of its side)")
    -- and springs back, less its sag under its own weight: the floor holds the bottom
    -- layer about 4 g / kappa above its goals and the other four hang g / kappa below
    -- theirs, kappa = 0.4 / 0.6 * 60^2 = 2400 / s^2: 5 g / kappa = 2 cm, 4% (measured 4.9%)
    expect.gt(hj, 0.93, "the jelly springs back")
    expect.lt(js:strain(), 0.05, "... to its shape (the cluster's strain)")
    expect.lt(hd, hj - 0.1, "the plastic one keeps a dent (measured 0.81 of its side)")
    expect.gt(gap, 0.1, "the cubes never meet")
  end)
end
