-- symmetric_drop.lua: a mirror-symmetric scene stays symmetric. A 5 kg box dropped flat
-- and centred from 26 cm onto a soft lattice block (on a ground plane; world damping 1,
-- 15 substeps, one iteration) must land and come to rest upright: nothing in the scene
-- tells it which way to turn. One Gauss-Seidel sweep per substep is far from converged,
-- so it leans the way its colour batches follow each other: with the constraints
-- coloured in creation order the box turned (0.3 rad/s on a damped jelly; on a stiff
-- light block that throws it back up, 2.9 rad/s). Mirror images are now coloured alike
-- (src/core/colour.c), so each sweep of a symmetric body is symmetric and the block and
-- the box keep their symmetry to rounding. With an odd number of particles across, some
-- lie on the mirror planes: the links that meet at one are mirror images that cannot
-- share a batch, and no colouring is symmetric. They are projected together instead, each
-- from the same positions (colour.c's compounds; before that a box dropped on a 7 x 4 x 7
-- block turned at 0.15-0.7 rad/s, on a stiff 5^3 block at 3.3 rad/s). (The Kuhn split of a
-- lattice's cells into tets is not symmetric, so the blocks have none.)

-- a block of n x ny x n particles, 1 m wide and h tall, centred on x = z = 0; the box
-- (half height hy) 26 cm above it
local function drop(o)
  local w = wobble.world{ substeps = 15, damping = 1 }
  w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = o.ground_friction }
  -- one radius above the ground: made touching it, not inside it
  local block = w:lattice{ min = {-0.5, o.r, -0.5}, max = {0.5, o.h + o.r, 0.5}, res = {o.n, o.ny, o.n},
                           mass = o.mass, radius = o.r, compliance = o.compliance, damping = o.damping,
                           friction = 0.5 }
  local top = o.h + 2 * o.r -- the block's top face: its top particles' spheres
  local box = w:rigid{ shape = "box", half = {0.25, o.hy, 0.25}, mass = 5, pos = {0, top + o.hy + 0.26, 0},
                       friction = o.box_friction }
  local r = { spin = 0, tilt = 0, contacts = 0, lowest = math.huge, top = top }
  w:run{ seconds = 4, on_frame = function(w)
    local ox, oy, oz = box:angular_velocity()
    r.spin = math.max(r.spin, math.sqrt(ox * ox + oy * oy + oz * oz))
    -- tilt: the angle between the box's up axis and the vertical
    local _, qx, _, qz = box:rotation()
    r.tilt = math.max(r.tilt, math.deg(2 * math.asin(math.min(1, math.sqrt(qx * qx + qz * qz)))))
    r.contacts = math.max(r.contacts, w:stats().rigid_contacts)
    local _, y = box:position()
    r.lowest = math.min(r.lowest, y - o.hy)
  end }
  -- the block's mirror error: each particle against its images across x = 0 and z = 0
  r.asym = 0
  local function at(i, j, k) return w:position(block.first + i + (j + k * o.ny) * o.n) end
  for k = 0, o.n - 1 do
    for j = 0, o.ny - 1 do
      for i = 0, o.n - 1 do
        local x, y, z = at(i, j, k)
        local xm, ym = at(o.n - 1 - i, j, k)
        local _, yz, zm = at(i, j, o.n - 1 - k)
        r.asym = math.max(r.asym, math.abs(x + xm), math.abs(y - ym), math.abs(z + zm), math.abs(y - yz))
      end
    end
  end
  local vx, vy, vz = box:velocity()
  r.speed = math.sqrt(vx * vx + vy * vy + vz * vz)
  print(string.format("%s: spin %.2e rad/s, tilt %.2e deg, block mirror error %.2e m, box bottom down to %.3f m "
                      .. "(block top %.3f m), %d contacts", o.name, r.spin, r.tilt, r.asym, r.lowest, top, r.contacts))
  return r
end

local scenes = {
  -- box_on_jelly's jelly without its tets (creation order: 0.30 rad/s, 1.2 degrees)
  { name = "a damped jelly", n = 8, ny = 5, h = 0.5, r = 0.0625, mass = 3, compliance = 5e-3, damping = 5,
    hy = 0.12, ground_friction = 0.8, box_friction = 0.6 },
  -- stiff and light: the box bounces (creation order: 2.9 rad/s)
  { name = "a stiff light block", n = 6, ny = 6, h = 1, r = 0.1, mass = 1, compliance = 1e-3, damping = 1,
    hy = 0.1, ground_friction = 0.5, box_friction = 0.5 },
  -- the same with particles on the mirror planes (links each projected alone: 0.15 and
  -- 3.3 rad/s, mirror errors 3e-3 and 2e-3 m)
  { name = "a damped jelly 7 x 4 x 7", n = 7, ny = 4, h = 0.5, r = 0.0625, mass = 3, compliance = 5e-3, damping = 5,
    hy = 0.12, ground_friction = 0.8, box_friction = 0.6 },
  -- (the box rests on a particle at its centre here, and the box's contacts are projected
  -- one after another: its mirror error is 7e-7 m, 1e-5 allowed)
  { name = "a stiff light block 5 x 5 x 5", n = 5, ny = 5, h = 1, r = 0.1, mass = 1, compliance = 1e-3, damping = 1,
    hy = 0.1, ground_friction = 0.5, box_friction = 0.5, asym = 1e-5 },
}

for _, o in ipairs(scenes) do
  test("a box dropped flat and centred on " .. o.name .. " lands and stays upright", function()
    local r = drop(o)
    -- the scene did what it is about: the box came down on the block, pressed into it
    -- on many particles and stayed on it
    expect.gt(r.contacts, 8, "rests on many particles")
    expect.lt(r.lowest, r.top - 0.005, "pressed into the block")
    expect.gt(r.lowest, 0.3, "held above the ground")
    expect.lt(r.speed, 0.05, "at rest after 4 s")
    -- upright: never turning faster than 0.05 rad/s nor tilting by a degree
    expect.lt(r.spin, 0.05, "never spins")
    expect.lt(r.tilt, 1, "never tilts (degrees)")
    -- and symmetric to rounding (measured 8e-9 m to 7e-8 m; creation order: 4e-3 m)
    expect.lt(r.asym, o.asym or 1e-6, "the block mirrors itself across both planes")
  end)
end
