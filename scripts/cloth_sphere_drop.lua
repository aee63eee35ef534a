-- cloth_sphere_drop.lua: a fine self-colliding cloth (256 x 256 particles, 65 536) dropped
-- onto a sphere standing on the floor drapes over it, and its skirt folds onto itself on
-- the floor without passing through. A 2 x 2 m sheet, tilted a little and off the
-- sphere's axis so that it folds unevenly, falls 0.5 m onto a sphere of radius 0.3 m;
-- a flat sheet cannot lie on a sphere, so it gathers into folds down the sphere that
-- run out onto the floor and lie there on each other. self_collide = true with the
-- builder's radius (half the spacing: neighbours' spheres touch, so the particles cover
-- the sheet and collide as particles alone); rest neighbours (linked, or joined by a
-- bend) never collide. Soft in bending (dihedral bends of compliance 1e6 rad/(N m)) so
-- it folds finely; 20 substeps (with 10 the sheet, 256 links across, is softer and
-- spreads into a smooth tent whose fine folds barely touch: 194 contacts against 3100);
-- friction on the sphere, the floor and the cloth holds the drape; air drag (world
-- damping 0.5 /s) lets it settle.
-- The summary line gives the lowest and highest particle, the footprint, the closest
-- two particles in contact (over their contact distance r_i + r_j) and the mean ms per
-- frame (w:stats().step_ms).
-- tests/validation/cloth_sphere_drop.lua checks the claim at res = 48.
-- Try --set self_collide=0 to watch the folds pass through each other.
-- Run: build/wobble run scripts/cloth_sphere_drop.lua [--record out/drop/] [--set png=1]
-- Options: --set res=64 (particles across; 256), --set seconds=4, --set tilt=0.15 (rad),
--          --set sphere=0.3 (radius, m), --set height=0.5 (drop, m), --set substeps=20,
--          --set bend=1e6 (compliance), --set png=1 (the last frame: out/cloth_sphere_drop.png)
local args = wobble.args
local res = args.res or 256
local size = args.size or 2 -- m, the sheet's side
local R = args.sphere or 0.3 -- m, the sphere's radius; it stands on the floor
local w = wobble.world{ substeps = args.substeps or 20, iterations = 1, damping = args.damping or 0.5 }
w:collider{ shape = "plane", normal = {0, 1, 0}, offset = 0, friction = 0.6 }
w:collider{ shape = "sphere", center = {0, R, 0}, radius = R, friction = 0.6 }
local cloth = w:cloth{ origin = {-size / 2, 0, -size / 2}, size = {size, size}, res = {res, res}, mass = 0.8,
                       compliance = 1e-6, bend = args.bend or 1e6, self_collide = args.self_collide ~= 0,
                       friction = 0.5 }
local r = w:radius(cloth.particles[1])

-- tilt the flat sheet about the x axis, then about y by a third of that, shift it off the
-- sphere's axis and lift it so its lowest point is `height` above the sphere's top
local tilt, height = args.tilt or 0.15, args.height or 0.5
local ct, st, cy, sy = math.cos(tilt), math.sin(tilt), math.cos(tilt / 3), math.sin(tilt / 3)
local placed, low = {}, math.huge
for k, p in ipairs(cloth.particles) do
  local x, _, z = w:position(p)
  local y1, z1 = z * st, z * ct
  local x2, z2 = x * cy + z1 * sy, -x * sy + z1 * cy
  placed[k] = { x2 + 0.07 * size, y1, z2 + 0.04 * size }
  low = math.min(low, y1)
end
for k, p in ipairs(cloth.particles) do
  local q = placed[k]
  w:set_position(p, q[1], q[2] - low + 2 * R + height + r, q[3])
end

-- the camera `--record` draws with and `wobble view` starts with: from above at a slant,
-- far enough back to hold the sheet where it starts (1.1-1.4 m up) and the drape below
wobble.camera{ eye = {2.3, 2.4, 3.3}, target = {0, 0.65, 0} }

local seconds = args.seconds or 4
local ms, frames = 0, 0
w:run{ seconds = seconds, on_frame = function(w, f)
  ms, frames = ms + w:stats().step_ms, frames + 1
  if f % 60 == 0 and not args.quiet then
    local _, miny, _, _, maxy = w:bounds()
    print(string.format("frame %d: %.3f to %.3f m, %d particle contacts, %.0f ms/frame", f, miny, maxy,
                        w:stats().particle_contacts, w:stats().step_ms))
  end
end }

-- the closest two particles in contact (the last substep's pairs), over r_i + r_j: below 1
-- by the substep's slack at most; tests/validation/cloth_sphere_drop.lua checks every pair
-- that may collide on its own, without the engine's list
local closest = math.huge
for _, c in ipairs(w:contacts()) do
  if c.kind == "particle" then
    local ax, ay, az = w:position(c.a)
    local bx, by, bz = w:position(c.b)
    local d = math.sqrt((ax - bx) ^ 2 + (ay - by) ^ 2 + (az - bz) ^ 2)
    closest = math.min(closest, d / (w:radius(c.a) + w:radius(c.b)))
  end
end

local minx, miny, minz, maxx, maxy, maxz = w:bounds()
print(string.format("cloth sphere drop: %d x %d particles (r = %.4f m), %.3f to %.3f m above the floor (sphere top %.2f), "
                    .. "footprint %.2f x %.2f m; closest contact %.3f of r_i + r_j (%s); "
                    .. "%d particle contacts; %.0f ms/frame over %d frames",
                    res, res, r, miny, maxy, 2 * R, maxx - minx, maxz - minz, closest,
                    closest < 1 and "overlapping by the substep's slack" or "apart", w:stats().particle_contacts, ms / math.max(frames, 1),
                    frames))

-- --set png=1: the last frame as out/cloth_sphere_drop.png, the sheet in its own colour
-- (no strain colours), as docs/cloth_sphere_drop.png was made
if args.png then
  local pic = wobble.renderer{ width = 1280, height = 720 }
  pic:camera(wobble.camera())
  pic:draw(w, { constraints = false, materials = false })
  pic:save_png("cloth_sphere_drop.png")
  pic:close()
end
