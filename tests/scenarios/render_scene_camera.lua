-- render_scene_camera.lua: wobble.camera, the scene's camera (the one `wobble run
-- --record` draws with and `wobble view` starts with; tests/render/run.sh checks the
-- recording): set, read back, given back to the automatic framing, and its errors.

test("wobble.camera: none at first, set, read back, given back", function()
  expect.eq(wobble.camera(), nil, "no scene camera until one is set")
  wobble.camera{ eye = {1, 2, 3}, target = {0, 0.5, 0} }
  local c = wobble.camera()
  expect.eq(c.eye[1], 1); expect.eq(c.eye[2], 2); expect.eq(c.eye[3], 3)
  expect.eq(c.target[2], 0.5)
  expect.eq(c.up[2], 1, "up defaults to +y"); expect.eq(c.fov, 40, "fov defaults to 40 degrees")
  -- a script's own renderer takes it as it is
  local r = wobble.renderer{ width = 32, height = 24, backend = "null" }
  r:camera(wobble.camera())
  r:draw(wobble.world{})
  local got = r:get_camera()
  expect.eq(got.eye[3], 3); expect.eq(got.fov, 40)
  wobble.camera(false)
  expect.eq(wobble.camera(), nil, "false gives the framing back to the automatic camera")
end)

test("wobble.camera: bad cameras are refused and change nothing", function()
  wobble.camera{ eye = {0, 1, 4}, target = {0, 1, 0}, fov = 30 }
  expect.error(function() wobble.camera{ target = {0, 0, 0} } end, "eye")
  expect.error(function() wobble.camera{ eye = {0, 0, 1}, target = {0, 0, 1} } end, "must differ")
  expect.error(function() wobble.camera{ eye = {0, 0, 1}, target = {0, 0, 0}, fov = 180 } end, "fov")
  expect.error(function() wobble.camera{ eye = {0, 2, 0}, target = {0, 0, 0} } end, "up")
  expect.error(function() wobble.camera{ eye = {0, 0, 1}, target = {0, 0, 0}, zoom = 2 } end, "zoom")
  expect.error(function() wobble.camera(3) end, "table expected")
  expect.eq(wobble.camera().fov, 30, "the camera set before is kept")
  wobble.camera(false)
end)
