-- rope_winch.lua: a rope wound on a spinning DYNAMIC drum. The drum is a rigid capsule
-- lying along z, spinning about its axis, held on its axle by a grab at its centre
-- (w:grab(drum, {0,0,0}): a force through the axis, so it can turn but not wander). A
-- rope lies straight out from the drum's top, its end attached to the drum's surface
-- (w:attach(p, drum)), a small weight at its far end. Gravity is off: nothing acts but the
-- drum and the rope on each other. The drum drags the rope's end round, the rope winds
-- on, and the drum slows as it hands its angular momentum to the rope.
-- Run: build/wobble run scripts/rope_winch.lua [--record out/winch/] [--set omega=3]
--      build/wobble test scripts/rope_winch.lua   (runs it and checks the claims)
--      --set attach=0: the rope's end is not attached (the checks then fail)
local args = wobble.args
local omega = tonumber(args.omega) or 3          -- rad/s, the drum's spin at the start
local seconds = tonumber(args.seconds) or 2.4    -- about one turn of winding
local attach = (tonumber(args.attach) or 1) ~= 0
local R, segments, length = 0.25, 30, 1.5

-- no velocity damping: it would take angular momentum out
local w = wobble.world{ gravity = {0, 0, 0}, substeps = 40, iterations = 2, damping = 0 }
local drum = w:rigid{ shape = "capsule", a = {0, 0, -0.4}, b = {0, 0, 0.4}, radius = R, mass = 20,
                      angular_velocity = {0, 0, omega}, friction = 0.5 }
local axle = w:grab(drum, {0, 0, 0})

-- the rope lies along +x, tangent to the drum's top; a counter-clockwise spin winds it
local r = length / segments / 2
local rope = w:rope{ from = {0, R + r, 0}, to = {length, R + r, 0}, segments = segments, mass = 0.2, radius = r }
local top = rope.particles[1]
local hook = attach and w:attach(top, drum) or nil
local weight = w:particle{ pos = {length + 0.1, R + r, 0}, mass = 0.1, radius = 0.05 }
w:distance(rope.particles[#rope.particles], weight)

local function Lz() return select(3, w:angular_momentum()) end -- about the origin: the axle
local L0 = Lz()
local I = L0 / omega -- the drum alone carries it at the start
w:run{ seconds = seconds }

-- particles lying on the drum: centres at R + r from the axis, to half a radius
local wrapped = 0
for _, p in ipairs(rope.particles) do
  local x, y = w:position(p)
  if math.abs(math.sqrt(x * x + y * y) - (R + r)) < 0.5 * r then wrapped = wrapped + 1 end
end
local om = select(3, drum:angular_velocity())
local L1 = Lz()
print(string.format("winch: the drum slowed from %.3f to %.3f rad/s (its share of L: %.1f %%); %d of %d rope "
  .. "particles lie on it; total L_z %.6f -> %.6f (%.2e relative); the axle holds %.3f N",
  omega, om, 100 * I * om / L1, wrapped, #rope.particles, L0, L1, L1 / L0 - 1, axle:force()))

if test then  -- under `wobble test`: the header's claims
  test("the rope winds on the spinning drum and slows it; angular momentum is kept", function()
    -- several particles lie on the drum's surface: the rope wound on (without the
    -- attachment the drum slides under the rope and 2 particles touch it)
    expect.ge(wrapped, 8, "wound particles")
    -- the drum handed a good part of its angular momentum to the rope (the rope, 0.3 kg
    -- out to 1.6 m, can take much of the drum's 0.59 kg m^2 x 3 rad/s)
    expect.lt(om, 0.9 * omega, "the drum slowed")
    -- nothing outside acts about the axis: gravity is off, the axle's force passes through
    -- it (the drum's centre stays on the grab's target to 1e-7 m). The exchange through the
    -- attachment and the contacts keeps angular momentum to first order in h (the body's
    -- velocities come from its poses): measured 2.5e-3 at 20 substeps, 1.0e-3 at 40,
    -- 0.67e-3 at 80 over these 2.4 s; 3e-3 allows 3 x the measured value
    expect.rel(L1, L0, 3e-3, "total angular momentum about the axis")
    local x, y = drum:position()
    expect.lt(math.sqrt(x * x + y * y), 1e-6, "the drum stays on its axle")
    expect.truthy(hook and hook:valid(), "the rope's end is attached")
  end)
end
