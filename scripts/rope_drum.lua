-- rope_drum.lua: a winch. A rope hangs from a drum (a kinematic capsule) with its top
-- end attached to the drum's surface (w:attach); a weight hangs from its bottom end. The
-- drum turns and carries the attached end round: the rope winds on, and the weight
-- rises by the winding radius (drum radius + the rope's particle radius) times the
-- angle turned. Nothing moves the rope but the drum's turning.
-- Run: build/wobble run scripts/rope_drum.lua [--record out/drum/] [--set omega=1.5]
--      build/wobble test scripts/rope_drum.lua   (runs it and checks the rise)
local args = wobble.args
local omega = tonumber(args.omega) or 1.5       -- rad/s
local seconds = tonumber(args.seconds) or 4     -- of turning: under a full turn, so the
                                                -- rope winds in one layer
local R, segments, length = 0.25, 50, 2.5

-- 40 substeps, 2 iterations: a 50-link chain carrying 1.5 kg stretches well under 1 %
local w = wobble.world{ substeps = 40, iterations = 2, damping = 0.2 }
local centre = {0, 1.5, 0}
local drum = w:collider{ shape = "capsule", a = {0, 1.5, -0.4}, b = {0, 1.5, 0.4}, radius = R, friction = 0.5 }
-- the axle's stand, for the eye (the rope never reaches it)
w:collider{ shape = "box", center = {0, 0.75, -0.72}, half = {0.06, 0.75, 0.04} }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = -1.5 }

-- the rope starts on the drum's side (x = R + r) and hangs straight down
local r = length / segments / 2                  -- the builders' default radius: half the spacing
local x0 = R + r
local rope = w:rope{ from = {x0, centre[2], 0}, to = {x0, centre[2] - length, 0}, segments = segments,
                     mass = 0.5, radius = r }
local top, bottom = rope.particles[1], rope.particles[#rope.particles]
local hook = w:attach(top, drum)
-- the weight: 1 kg on a short link below the rope's end (longer than the two radii: the
-- weight and the rope's end would push each other apart)
local weight = w:particle{ pos = {x0, centre[2] - length - 0.15, 0}, mass = 1, radius = 0.08 }
w:distance(bottom, weight)

-- settle hanging, then turn
w:run{ seconds = 1 }
local y_start = select(2, w:position(weight))
drum:set_angular_velocity(0, 0, omega)
w:run{ seconds = seconds }
drum:set_angular_velocity(0, 0, 0)
w:run{ seconds = 1 }                             -- let the weight settle

local y_end = select(2, w:position(weight))
local angle = omega * seconds
local rise, expected = y_end - y_start, (R + r) * angle
local f = hook:force()
local strain = w:max_strain()
print(string.format("drum: turned %.2f rad; the weight rose %.3f m, (R + r) x angle = %.3f m (%.2f%% off); "
  .. "the hook holds %.2f N (the drum's contact carries the rest of the %.2f N)",
  angle, rise, expected, 100 * (rise - expected) / expected, f, (0.5 + 1) * 9.81))

if test then  -- under `wobble test`: the header's claim
  test("the rope winds on the turning drum: the weight rises by (R + r) x angle", function()
    -- the wound links are chords of the circle (0.05 m on 0.275 m: 0.1 % short of the
    -- arc), and the links stretch under the load, less where friction on the drum
    -- holds part of it (w:max_strain() stays under 1 %): 2 %
    expect.lt(strain, 0.01, "the rope barely stretches")
    expect.rel(rise, expected, 0.02, "rise of the weight")
    -- the attached end went round with the drum: it is at angle omega t on the circle
    local x, y = w:position(top)
    local a = math.atan(y - centre[2], x - centre[1])
    expect.near(a, angle - 2 * math.pi * math.floor((angle + math.pi) / (2 * math.pi)), 1e-6,
                "the attached end turned with the drum")
    expect.near(math.sqrt(x * x + (y - centre[2]) ^ 2), x0, 1e-9, "on the drum's surface, where it was attached")
  end)
end
