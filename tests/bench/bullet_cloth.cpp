// bullet_cloth.cpp: the Bullet peer of wobble's cloth benchmark scenes (tests/bench/cloth128.lua).
// The same scene in Bullet's btSoftBody (Debian's libbullet-dev), one thread, run as a
// process of its own by the Lua scene, which prints the ratio. Built by `make bench`:
//   g++ -O3 -march=native tests/bench/bullet_cloth.cpp $(pkg-config --cflags --libs bullet)
//   build-bench/bullet_cloth n=128 frames=120 substeps=10 iterations=1 size=2 height=1
//
// The scene, as wobble's w:cloth{origin = {-s/2, y, -s/2}, size = {s, s}, res = {n, n}}:
// an n x n sheet in the x-z plane at height y, total mass m, pinned at corners (0, 0) and
// (n-1, 0), falling under gravity onto the ground, no friction, no air, no damping.
// - links: the structural links and one diagonal per cell, alternating between cells, as
//   wobble's cloth with shear = true and CreatePatch with gendiags (n = 128: 48,641 in all
//   three), as stiff as Bullet goes (kLST = 1; wobble's compliance 0).
// - the sheet: nodes and links alone by default; patch=1 builds it with CreatePatch, whose
//   faces cost Bullet normals and face updates every step that wobble's step does not do
//   (measured: about 10 % more CPU time at n = 128).
// - work per frame: wobble's substeps x iterations map to Bullet's internal steps x
//   m_cfg.piterations: one frame of dt is stepSimulation(dt, S, dt/S), S internal steps of
//   dt/S (the tick count is reported; float time accumulation could shift a step to the
//   next frame), each predicting, colliding and sweeping every link piterations times, as
//   one wobble substep with iterations = piterations. Bullet's other solvers stay at their
//   defaults (viterations = diterations = 0). The links are put in random order
//   (randomizeConstraints, see below; ordered=1 keeps creation order).
// - ground: wobble's plane is a static box here (Bullet's soft-rigid collision works on the
//   sparse SDF of convex shapes; btStaticPlaneShape is concave); the sheet's collision
//   margin is the particle radius.
// - timing: the stepping loop alone, after one untimed frame: wall clock (as wobble's
//   w:stats().step_ms) and the process's CPU time (steadier on a busy machine). Memory:
//   resident memory grown from before the world to the end, per node.
// Output: one line of JSON; exit code 3 when the sheet blew up (a node below -0.5 m or
// above its start + 0.5 m, or not a number), 2 for a bad argument.
#include <btBulletDynamicsCommon.h>
#include <BulletSoftBody/btSoftBodyHelpers.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>

static long ticks = 0;
static void on_tick(btDynamicsWorld *, btScalar) { ticks++; }

// resident set size in bytes (Linux), 0 when unknown
static double rss_bytes() {
    FILE *f = fopen("/proc/self/status", "r");
    if (!f) return 0;
    char line[256];
    double kb = 0;
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, "VmRSS:", 6)) kb = atof(line + 6);
    fclose(f);
    return kb * 1024;
}

static double now(clockid_t c = CLOCK_MONOTONIC) {
    timespec t;
    clock_gettime(c, &t);
    return t.tv_sec + t.tv_nsec * 1e-9;
}

int main(int argc, char **argv) {
    // key=value arguments, the names of the Lua scene's fields
    int n = 128, frames = 300, substeps = 10, iterations = 1;
    bool patch = false, ordered = false;
    double size = 2, height = 1, mass = 1, radius = 0.02, dt = 1.0 / 60, gravity = -9.81;
    for (int i = 1; i < argc; i++) {
        const char *eq = strchr(argv[i], '=');
        if (!eq) { fprintf(stderr, "bullet_cloth: expected key=value, got '%s'\n", argv[i]); return 2; }
        const std::string k(argv[i], eq - argv[i]);
        const double v = atof(eq + 1);
        if (k == "n") n = (int)v;
        else if (k == "frames") frames = (int)v;
        else if (k == "substeps") substeps = (int)v;
        else if (k == "iterations") iterations = (int)v;
        else if (k == "size") size = v;
        else if (k == "height") height = v;
        else if (k == "mass") mass = v;
        else if (k == "radius") radius = v;
        else if (k == "dt") dt = v;
        else if (k == "patch") patch = v != 0;
        else if (k == "ordered") ordered = v != 0;
        else { fprintf(stderr, "bullet_cloth: unknown key '%s'\n", k.c_str()); return 2; }
    }
    if (n < 2 || frames < 1 || substeps < 1 || iterations < 1) {
        fprintf(stderr, "bullet_cloth: n >= 2, frames, substeps and iterations >= 1\n");
        return 2;
    }
    const double rss0 = rss_bytes();

    btSoftBodyRigidBodyCollisionConfiguration config;
    btCollisionDispatcher dispatcher(&config);
    btDbvtBroadphase broadphase;
    btSequentialImpulseConstraintSolver solver;
    btSoftRigidDynamicsWorld world(&dispatcher, &broadphase, &solver, &config);
    const btVector3 g(0, (btScalar)gravity, 0);
    world.setGravity(g);
    btSoftBodyWorldInfo &info = world.getWorldInfo();
    info.m_gravity = g;
    info.air_density = 0;  // no aerodynamics (kDG = kLF = 0 too): wobble has none
    world.setInternalTickCallback(on_tick);

    // the ground: a static box whose top face is y = 0, wider than any sheet
    const btScalar half = (btScalar)(size + 10);
    btBoxShape ground_shape(btVector3(half, 1, half));
    btTransform t;
    t.setIdentity();
    t.setOrigin(btVector3(0, -1, 0));
    btDefaultMotionState ground_state(t);
    btRigidBody ground(btRigidBody::btRigidBodyConstructionInfo(0, &ground_state, &ground_shape));
    ground.setFriction(0);
    world.addRigidBody(&ground);

    const btScalar h = (btScalar)(size / 2), y = (btScalar)height;
    btSoftBody *cloth;
    if (patch) {  // Bullet's helper: the same links, plus faces (normals, aero) every step
        cloth = btSoftBodyHelpers::CreatePatch(info, btVector3(-h, y, -h), btVector3(h, y, -h), btVector3(-h, y, h),
                                               btVector3(h, y, h), n, n, 1 + 2, true);  // pins: corners 00 and 10
    } else {      // nodes and links alone, in CreatePatch's (and wobble's) layout
        btAlignedObjectArray<btVector3> x;
        btAlignedObjectArray<btScalar> m;
        x.resize(n * n);
        m.resize(n * n);
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                x[i + j * n] = btVector3(-h + 2 * h * i / (n - 1), y, -h + 2 * h * j / (n - 1));
                m[i + j * n] = 1;
            }
        m[0] = m[n - 1] = 0;  // pins: corners 00 and 10
        cloth = new btSoftBody(&info, n * n, &x[0], &m[0]);
        for (int j = 0; j < n; j++)
            for (int i = 0; i < n; i++) {
                const int a = i + j * n;
                if (i + 1 < n) cloth->appendLink(a, a + 1);
                if (j + 1 < n) cloth->appendLink(a, a + n);
                if (i + 1 < n && j + 1 < n) {  // one diagonal per cell, alternating
                    if ((i + j) % 2 == 0) cloth->appendLink(a, a + n + 1);
                    else cloth->appendLink(a + 1, a + n);
                }
            }
    }
    cloth->m_materials[0]->m_kLST = 1;
    // Bullet's Gauss-Seidel sweeps the links in creation order, row by row from the pinned
    // edge: with piterations = 1 a sheet of 48 x 48 or more then blows up within 20 frames
    // (also without the ground). Bullet's own remedy, used by its cloth demos, is a random
    // order; wobble sweeps its links in colour batches instead.
    if (!ordered) cloth->randomizeConstraints();
    cloth->m_cfg.piterations = iterations;
    cloth->m_cfg.kDP = 0;  // no damping: wobble's world damping is 0
    cloth->m_cfg.kDF = 0;  // no friction: wobble's collider friction is 0
    cloth->getCollisionShape()->setMargin((btScalar)radius);
    cloth->setTotalMass((btScalar)mass);
    world.addSoftBody(cloth);

    const btScalar fdt = (btScalar)dt, h_sub = (btScalar)(dt / substeps);
    world.stepSimulation(fdt, substeps, h_sub);  // untimed: first-step set-up, as wobble's scene
    info.m_sparsesdf.GarbageCollect();
    ticks = 0;
    const double t0 = now(), c0 = now(CLOCK_PROCESS_CPUTIME_ID);
    for (int f = 0; f < frames; f++) {
        world.stepSimulation(fdt, substeps, h_sub);
        info.m_sparsesdf.GarbageCollect();  // once a frame, as Bullet's soft-body demos do
    }
    const double secs = now() - t0, cpu = now(CLOCK_PROCESS_CPUTIME_ID) - c0, rss1 = rss_bytes();

    // sanity: the sheet hangs and lies on the ground, it did not blow up
    double ymin = 1e30, ymax = -1e30;
    for (int i = 0; i < cloth->m_nodes.size(); i++) {
        const double py = cloth->m_nodes[i].m_x.y();
        if (py < ymin) ymin = py;
        if (py > ymax) ymax = py;
    }
    const int nodes = cloth->m_nodes.size(), links = cloth->m_links.size();
    const bool blew_up = !(ymin > -0.5 && ymax < height + 0.5);  // also NaN
    printf("{\"engine\": \"bullet\", \"particles\": %d, \"links\": %d, \"frames\": %d, \"ticks_per_frame\": %.4f, "
           "\"piterations\": %d, \"ms_per_frame\": %.4f, \"cpu_ms_per_frame\": %.4f, \"ns_per_projection\": %.3f, \"bytes_per_particle\": %.1f, "
           "\"y_min\": %.4f, \"y_max\": %.4f, \"scalar_bytes\": %d}\n",
           nodes, links, frames, (double)ticks / frames, iterations, secs * 1e3 / frames, cpu * 1e3 / frames,
           secs * 1e9 / ((double)ticks * iterations * links), rss1 > rss0 ? (rss1 - rss0) / nodes : 0.0, ymin, ymax,
           (int)sizeof(btScalar));
    if (blew_up) {  // timing a sheet that blew up compares nothing
        fprintf(stderr, "bullet_cloth: the sheet blew up (y from %g to %g)\n", ymin, ymax);
        return 3;
    }
    world.removeSoftBody(cloth);
    delete cloth;
    world.removeRigidBody(&ground);
    return 0;
}
