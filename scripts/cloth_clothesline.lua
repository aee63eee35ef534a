-- cloth_clothesline.lua: the reference thesis's clothesline (its Figure 12).
-- A square of cloth pegged to a line at its corners and middle falls, swings and
-- comes to hang; the links stretch under its weight and are drawn red where they do.
-- Air drag (world damping) lets it settle: --set drag=0 keeps it swinging.
-- Run: build/wobble run scripts/cloth_clothesline.lua [--set res=40] [--set seconds=6]
--      build/wobble run scripts/cloth_clothesline.lua --record out/clothesline.mp4
local args = wobble.args
local res = args.res or 30
local w = wobble.world{ gravity = {0, -9.81, 0}, substeps = 20, iterations = 1, damping = args.drag or 0.5 }

w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.6 }

-- start horizontal, level with the line, so the fall swings it down into place
local cloth = w:cloth{ origin = {-0.75, 2, 0}, size = {1.5, 1.5}, res = {res, res},
                       mass = 0.3, compliance = 2e-6, bend = 100 }
-- the line: a thin capsule the cloth is pegged under, touching the pegged edge's
-- particles (contact radius: half their spacing) without overlapping them: a particle
-- made inside a collider would be pushed out slowly (max_depenetration), sagging the
-- pegged edge over the line for the first frames
local r = w:radius(cloth.particles[1])
w:collider{ shape = "capsule", a = {-1.5, 2 + r + 0.011, 0}, b = {1.5, 2 + r + 0.011, 0}, radius = 0.01 }
-- the pegs: the two corners on the line (z = 0) and the middle of that edge
local pegged = cloth:pin_where(function(x, y, z)
  return z < 1e-6 and (math.abs(x + 0.75) < 1e-6 or math.abs(x - 0.75) < 1e-6 or math.abs(x) < 0.76 / (res - 1))
end)

local seconds = args.seconds or 6
w:run{ seconds = seconds, on_frame = function(w, f, t)
  if f % 60 == 0 and not args.quiet then
    local ke = w:energy()
    print(string.format("t=%4.1fs  kinetic %.4f J  max strain %5.1f%%", t, ke, 100 * w:max_strain()))
  end
end }

-- the strain a drawing colours full red (its legend's +x %): the 95th percentile of the
-- links' strain, not the maximum, which a few links at the pegs reach (r:draw's
-- strain_scale = "auto"), worked out by drawing the last frame small
local scale = wobble.renderer{ width = 320, height = 200, samples = 1 }
scale:draw(w)
local shown = scale:strain_scale()
scale:close()
local minx, miny, minz, maxx, maxy, maxz = w:bounds()
print(string.format("clothesline: %d particles, %d pegged, %d frames; hangs from y=%.2f down to y=%.2f, max strain %.1f%% "
  .. "(at the pegs); the colours' full red, the legend's +%.2f%%, is the strain 95%% of the links stay under",
  w:particle_count(), pegged, w:frame(), maxy, miny, 100 * w:max_strain(), 100 * shown))

if test then  -- under `wobble test`: the header's claim
  test("the cloth hangs from the line, stretched by its weight", function()
    -- hanging: its top at the line (y = 2), its 1.5 m side down (measured 1.50 m at 6 s)
    expect.near(maxy, 2, 0.02, "held at the line")
    expect.gt(maxy - miny, 1.45, "hangs down its 1.5 m side (it still swings a little at 6 s)")
    expect.lt(maxy - miny, 1.5 * 1.05, "... by a few percent, not torn or fallen")
    -- stretched most at the pegs, where its whole weight hangs
    expect.gt(w:max_strain(), 0.01, "the links at the pegs stretch over 1%")
    expect.lt(shown, w:max_strain(), "the colour scale is below the maximum (a percentile)")
  end)
end
