-- sweep_drape.lua: a square cloth falls onto a sphere and drapes over it; how far it
-- sags and how much it stretches depend on its compliance and on the substep count.
-- A scene made for `wobble sweep`: it reads both from --set and reports its figures
-- with wobble.result (sag: how far the corners hang below the sphere's top, m;
-- max_strain: the largest stretch of a link at the end; stable: every position finite,
-- the centre still on the sphere and no link stretched past 50 %). An unstable run
-- ends with an error (exit 2) after reporting, so `wobble collect --plot` crosses it
-- out: too few substeps for a stiff cloth over-stretch it and it falls through.
-- Run: build/wobble run scripts/sweep_drape.lua --set compliance=1e-4 --set substeps=5
--      build/wobble sweep scripts/sweep_drape.lua --grid compliance=0,1e-6,1e-4,1e-3,1e-2 \
--        --grid substeps=1,2,5,10,20 --out out/drape --run
--      build/wobble collect out/drape --plot compliance,substeps,sag drape.png
local args = wobble.args
local compliance, substeps = args.compliance or 1e-6, args.substeps or 10
local w = wobble.world{ substeps = substeps }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.5 }
w:collider{ shape = "sphere", center = {0, 0.5, 0}, radius = 0.4, friction = 0.5 }
local cloth = w:cloth{ origin = {-0.8, 1.1, -0.8}, size = {1.6, 1.6}, res = {20, 20}, compliance = compliance,
                       bend = 10 }

-- the centre (nearest the sheet's middle) and the four corners
local centre, best = nil, math.huge
local corners = {}
for _, p in ipairs(cloth.particles) do
  local x, _, z = w:position(p)
  if x * x + z * z < best then centre, best = p, x * x + z * z end
  if math.abs(x) > 0.79 and math.abs(z) > 0.79 then corners[#corners + 1] = p end
end

w:run{ seconds = args.seconds or 2 }

local top = 0.9 -- the sphere's top
local sag, finite = 0, true
for _, p in ipairs(corners) do
  local _, y = w:position(p)
  sag = sag + (top - y) / #corners
end
for _, p in ipairs(cloth.particles) do
  local x, y, z = w:position(p)
  if x ~= x or y ~= y or z ~= z or math.abs(x) + math.abs(y) + math.abs(z) == math.huge then finite = false end
end
local _, cy = w:position(centre)
local strain = w:max_strain()
local stable = finite and cy > top - 0.05 and strain < 0.5
wobble.result{ sag = finite and sag or 0 / 0, max_strain = strain, centre_y = cy, stable = stable,
               warnings = (w:warnings()) }
print(string.format("compliance %g, %d substeps: sag %.3f m, max strain %.1f %%, %s", compliance, substeps, sag,
  100 * strain, stable and "stable" or "NOT stable"))
if test then -- under `wobble test`: at the defaults the cloth drapes, stable
  test("at the defaults the cloth drapes over the sphere: its centre on the top, its corners hanging", function()
    expect.truthy(stable, "stable")
    local r = w:radius(centre)
    -- resting on the sphere, a particle's centre is its radius r above the top (measured:
    -- 0.11 r lower, the sheet's weight on the contact)
    expect.near(cy, top + r, 0.25 * r, "the centre rests on the sphere's top")
    -- flat, the corners would be 0.2 m above the top; draped they hang well below it
    expect.gt(sag, 0.3, "the corners hang below the sphere's top (m)")
  end)
end
if not stable then
  error(string.format("unstable: max strain %.0f %%, centre at y = %.2f", 100 * strain, cy))
end
