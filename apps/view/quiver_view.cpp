// quiver-view: a baked model, live. Drag a surface point with the mouse (a spring to the cursor
// ray), let go and watch it ring; change integrator, time step, damping and gravity; browse the
// linear modes and basis vectors. With --free, a free model (or a --pile of them) drops onto a
// ground and the colliders: lift, drag and throw it; R drops it again. Steps at the model's fixed
// rate, whatever the frame rate.
// `--frames N --screenshot out.png [--drag-script FILE]` runs a bounded, deterministic session
// (1/60 s per frame) for tests and recordings.
#include <algorithm>
#include <cstdio>
#include <array>
#include <filesystem>
#include <iostream>
#include <optional>

#include <epoxy/gl.h>
// epoxy first: it replaces the GL header GLFW would include.
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>
#include <Eigen/Geometry>

#include "apps/render/collider_mesh.h"
#include "apps/render/software_renderer.h"
#include "apps/support/mesh_options.h"
#include "apps/view/drag_script.h"
#include "apps/view/orbit_camera.h"
#include "apps/view/render_basis_view.h"
#include "apps/view/surface_view.h"
#include "apps/view/view_session.h"

namespace quiver::app {

namespace {

constexpr double kScriptedFrameSeconds = 1.0 / 60;

struct ViewOptions {
  std::string model;
  std::vector<int> size{1280, 800};
  int frames = 0;  // > 0: stop after this many frames
  std::string screenshot;
  std::string dragScript;
  bool noPanel = false;
  bool gpuSkinning = false;  // draw the render mesh deformed in the vertex shader (render_basis_view.h)
  std::string showMode;  // "linear:N" or "basis:N": start in the mode browser
  ViewSettings settings;
  FlightSetup flight;    // with --free (settings.step.freeFlight)
};

// Free flight's defaults in the viewer: with no collider, a ground plane under the model as baked,
// and the model starting one height above it (so that it drops).
FlightSetup withViewerDefaults(FlightSetup flight, const qv_model_info& info) {
  if (!flight.colliders.empty()) return flight;
  flight.colliders.push_back("plane:0,0,1," + std::to_string(info.bbox_min[2]));
  if (flight.position == std::vector<double>{0, 0, 0}) flight.position[2] = info.bbox_max[2] - info.bbox_min[2];
  return flight;
}

// The box the camera frames: the model where it is first drawn (every body, in flight).
void startBox(const ViewSession& session, Eigen::Vector3d& lo, Eigen::Vector3d& hi) {
  std::vector<float> x;
  session.positions(x);
  lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (size_t v = 0; v < x.size() / 3; ++v)
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], double(x[3 * v + a])), hi[a] = std::max(hi[a], double(x[3 * v + a]));
  if (session.flight()) lo[2] -= hi[2] - lo[2];  // and the ground it falls to
}

// Body coordinates (rest + u) to the world: identity in place; in flight x + R (p - c).
Eigen::Matrix4f bodyToWorld(const qv_instance* body, const double centre[3]) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  qv_rigid_state s;
  if (qv_instance_get_rigid_state(body, &s) != QV_OK) return m;
  const Eigen::Matrix3d R =
      Eigen::Quaterniond(s.orientation[0], s.orientation[1], s.orientation[2], s.orientation[3]).normalized().toRotationMatrix();
  m.topLeftCorner<3, 3>() = R.cast<float>();
  m.topRightCorner<3, 1>() = (Eigen::Vector3d(s.position) - R * Eigen::Vector3d(centre)).cast<float>();
  return m;
}

// The window, its GL context and Dear ImGui, torn down in the right order.
class Window {
public:
  Window(int width, int height, const std::string& title, bool bounded) {
    glfwSetErrorCallback([](int, const char* description) { lastError() = description; });
    if (!glfwInit())
      throw std::runtime_error("cannot open a window (" + lastError() + "); without a display, run under xvfb-run");
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_SAMPLES, 4);
    window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (!window_) {
      glfwTerminate();
      throw std::runtime_error("cannot create an OpenGL 3.3 core window (" + lastError() + ")");
    }
    glfwMakeContextCurrent(window_);
    glfwSwapInterval(bounded ? 0 : 1);  // a bounded run does not wait for the display
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini left in the user's folder
    ImGui::StyleColorsDark();
  }
  // After the application's own GLFW callbacks are set: ImGui chains to them.
  void startImGui() {
    ImGui_ImplGlfw_InitForOpenGL(window_, true);
    ImGui_ImplOpenGL3_Init("#version 330 core");
    imgui_ = true;
  }
  ~Window() {
    if (imgui_) {
      ImGui_ImplOpenGL3_Shutdown();
      ImGui_ImplGlfw_Shutdown();
    }
    ImGui::DestroyContext();
    glfwDestroyWindow(window_);
    glfwTerminate();
  }
  GLFWwindow* get() const { return window_; }

private:
  static std::string& lastError() {
    static std::string message = "no reason given";
    return message;
  }
  GLFWwindow* window_ = nullptr;
  bool imgui_ = false;
};

// The front buffer as it will be shown, saved as a PNG (GL's rows run bottom-up).
void saveScreenshot(const std::string& path, int width, int height) {
  Image image(width, height);
  std::vector<uint8_t> rows(3 * static_cast<size_t>(width) * height);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, rows.data());
  const size_t stride = 3 * static_cast<size_t>(width);
  for (int y = 0; y < height; ++y)
    std::copy_n(&rows[stride * (height - 1 - y)], stride, &image.rgb[stride * y]);
  writePng(path, image);
}

class Viewer {
public:
  Viewer(const ViewOptions& o, const RuntimeModel& model)
      : o_(o), model_(model), session_(model, o.settings, withViewerDefaults(o.flight, model.info())),
        size_((Eigen::Vector3d(model.info().bbox_max) - Eigen::Vector3d(model.info().bbox_min)).norm()) {
    Eigen::Vector3d lo, hi;
    startBox(session_, lo, hi);
    camera_ = OrbitCamera::framing(lo, hi, double(o.size[0]) / o.size[1]);
    if (const FlightWorld* flight = session_.flight())
      for (int k = 0; k < flight->colliders().size(); ++k)
        appendCollider(flight->colliders()[k], flight->colliders().surface(k), lo, hi, world_);
    edited_ = session_.settings();
    for (int i = 0; i < QV_INTEGRATOR_COUNT; ++i) integratorLabels_[i] = qv_integrator_description(qv_integrator(i));
    for (int i = 0; i < QV_ELASTICITY_COUNT; ++i) elasticityLabels_[i] = qv_elasticity_description(qv_elasticity(i));
    for (int i = 0; i < QV_SOLVER_COUNT; ++i) solverLabels_[i] = qv_solver_description(qv_solver(i));
    if (!o.dragScript.empty()) script_ = DragScript::load(o.dragScript);
    if (!o.showMode.empty()) {
      const size_t colon = o.showMode.find(':');
      const std::string kind = o.showMode.substr(0, colon);
      size_t used = 0;
      try {
        modeIndex_ = colon == std::string::npos ? -1 : std::stoi(o.showMode.substr(colon + 1), &used);
      } catch (const std::exception&) {
        modeIndex_ = -1;
      }
      if ((kind != "linear" && kind != "basis") || modeIndex_ < 0 || modeIndex_ >= model.info().r ||
          colon + 1 + used != o.showMode.size())
        throw std::runtime_error("--show-mode " + o.showMode + ": expected linear:N or basis:N with N from 0 to " +
                                 std::to_string(model.info().r - 1));
      modeKind_ = kind == "linear" ? 1 : 2;
      session_.showMode(ModeKind(modeKind_), modeIndex_, modeAmplitude_ * size_);
    }
  }

  int run() {
    Window window(o_.size[0], o_.size[1], "quiver-view: " + std::filesystem::path(o_.model).filename().string(),
                  o_.frames > 0);
    glfwSetWindowUserPointer(window.get(), this);
    glfwSetScrollCallback(window.get(), [](GLFWwindow* w, double, double dy) {
      if (!ImGui::GetIO().WantCaptureMouse) static_cast<Viewer*>(glfwGetWindowUserPointer(w))->camera_.zoom(std::pow(0.9, dy));
    });
    glfwSetKeyCallback(window.get(), [](GLFWwindow* w, int key, int, int action, int) {
      if (action == GLFW_PRESS && !ImGui::GetIO().WantCaptureKeyboard && key == GLFW_KEY_R)
        static_cast<Viewer*>(glfwGetWindowUserPointer(w))->session_.reset();
    });
    window.startImGui();
    SurfaceView surface(session_.triangles(), session_.bodyCount() * model_.info().vertex_count);
    std::optional<SurfaceView> render;  // the render mesh, drawn instead when the model has one
    if (!session_.renderTriangles().empty())
      render.emplace(session_.renderTriangles(), session_.bodyCount() * model_.info().render_vertex_count);
    std::optional<RenderBasisView> gpu;  // --gpu-skinning: one body at a time, deformed in the shader
    RuntimeModel::RenderBasis basis;
    if (o_.gpuSkinning) {
      if (!render) throw std::runtime_error("--gpu-skinning needs a model baked with a render mesh");
      basis = model_.renderBasis();
      const float* rest = qv_model_render_rest_positions(model_.get());
      gpu.emplace(std::vector<float>(rest, rest + 3 * size_t(model_.info().render_vertex_count)), model_.shownTriangles(), basis.rows,
                  model_.info().r);
    }
    std::optional<SurfaceView> world;  // the colliders, still
    if (!world_.triangles.empty()) {
      world.emplace(world_.triangles, static_cast<int>(world_.positions.size() / 3));
      world->update(world_.positions, std::vector<float>(world_.positions.size(), 0.0f));
    }
    double last = glfwGetTime(), rateStart = last;
    long rateSteps = 0;
    for (int frame = 0; !glfwWindowShouldClose(window.get()) && (o_.frames == 0 || frame < o_.frames); ++frame) {
      glfwPollEvents();
      const double now = glfwGetTime();
      // Uncapped: advance() takes at most kMaxStepsPerFrame and reports when it falls behind.
      const double elapsed = o_.frames > 0 ? kScriptedFrameSeconds : now - last;
      last = now;
      int width = 0, height = 0, fbWidth = 0, fbHeight = 0;
      glfwGetWindowSize(window.get(), &width, &height);
      glfwGetFramebufferSize(window.get(), &fbWidth, &fbHeight);

      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      const ScriptedCursor cursor = readCursor(window.get(), frame, width, height);
      if (script_) {  // the scripted mouse clicks the panel too
        ImGui::GetIO().MousePos = ImVec2(static_cast<float>(cursor.x), static_cast<float>(cursor.y));
        ImGui::GetIO().MouseDown[0] = cursor.down;
      }
      ImGui::NewFrame();
      handleMouse(cursor, frame, width, height);
      rateSteps += session_.advance(elapsed);
      // Steps per wall-clock second, over the last half second (a running value before the first).
      if (now - rateStart > 0.05) stepsPerSecond_ = rateSteps / (now - rateStart);
      if (now - rateStart >= 0.5) {
        rateStart = now;
        rateSteps = 0;
      }
      energies_ = session_.energies();
      totalEnergy_[energyFrames_++ % totalEnergy_.size()] = static_cast<float>(energies_.kinetic + energies_.elastic);
      if (!o_.noPanel) panel();
      ImGui::Render();

      glViewport(0, 0, fbWidth, fbHeight);
      glClearColor(0.93f, 0.94f, 0.96f, 1);
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      session_.positions(positions_);
      const Eigen::Matrix4f view = camera_.view(), projection = camera_.projection(double(fbWidth) / std::max(fbHeight, 1));
      if (world) world->draw(view, projection, Eigen::Vector3f(0.62f, 0.6f, 0.56f), false);
      if (gpu && session_.drawsRenderMesh()) {
        for (int k = 0; k < session_.bodyCount(); ++k) {
          std::vector<double> q(static_cast<size_t>(model_.info().r));
          qv_instance_get_state(session_.body(k), q.data(), nullptr, nullptr);
          gpu->draw(view, projection, Eigen::Vector3f(0.27f, 0.51f, 0.71f), q, bodyToWorld(session_.body(k), basis.centre));
        }
      } else if (render && session_.drawsRenderMesh()) {
        session_.renderSurface(renderPositions_, renderNormals_);
        render->update(renderPositions_, renderNormals_);
        render->draw(view, projection, Eigen::Vector3f(0.27f, 0.51f, 0.71f), smoothNormals_);
      } else {
        session_.normals(positions_, normals_);
        surface.update(positions_, normals_);
        surface.draw(view, projection, Eigen::Vector3f(0.27f, 0.51f, 0.71f), smoothNormals_);
      }
      if (session_.grabbing()) {
        const int v = session_.grabbedVertex() + session_.grabbedBody() * model_.info().vertex_count;
        const Eigen::Vector3d& t = session_.grabTarget();
        surface.drawLines({positions_[3 * v], positions_[3 * v + 1], positions_[3 * v + 2], float(t.x()), float(t.y()),
                           float(t.z())},
                          view, projection, Eigen::Vector3f(0.85f, 0.25f, 0.2f));
      }
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
      if (o_.frames > 0 && frame + 1 == o_.frames && !o_.screenshot.empty()) saveScreenshot(o_.screenshot, fbWidth, fbHeight);
      glfwSwapBuffers(window.get());
    }
    if (o_.frames > 0) {
      std::printf("quiver-view: %d frames, %ld steps of %g s, %d resets, %d grabs\n", o_.frames, session_.stepsTaken(),
                  session_.config().time_step, session_.resets(), grabs_);
      for (int k = 0; session_.flight() && k < session_.bodyCount(); ++k) {
        qv_rigid_state s;
        qv_instance_get_rigid_state(session_.flight()->body(k).get(), &s);
        std::printf("quiver-view: body %d: centre %.4f %.4f %.4f m, velocity %.4f %.4f %.4f m/s\n", k, s.position[0],
                    s.position[1], s.position[2], s.linear_velocity[0], s.linear_velocity[1], s.linear_velocity[2]);
      }
    }
    return 0;
  }

private:
  // The cursor in window pixels and the left button, from the script or the mouse.
  ScriptedCursor readCursor(GLFWwindow* window, int frame, int width, int height) const {
    ScriptedCursor cursor;
    if (script_) {
      cursor = script_->at(frame);
      cursor.x *= width;
      cursor.y *= height;
    } else {
      glfwGetCursorPos(window, &cursor.x, &cursor.y);
      cursor.down = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS;
    }
    return cursor;
  }

  // A press on the panel is the panel's. Elsewhere it picks a surface point (drag it) or the
  // background (orbit); holding moves the spring's target in the plane through the picked point
  // facing the camera; release lets go.
  void handleMouse(ScriptedCursor cursor, int frame, int width, int height) {
    if (cursor.down && !mouseDown_ && ImGui::GetIO().WantCaptureMouse) cursor.down = false;
    const Ray ray = camera_.ray(cursor.x, cursor.y, width, height);
    if (cursor.down && !mouseDown_) {
      if (session_.press(ray, camera_.eye() - camera_.target)) {
        ++grabs_;
      } else if (script_) {
        std::fprintf(stderr, "quiver-view: warning: the scripted press at frame %d misses the model\n", frame);
      }
    } else if (cursor.down && session_.grabbing()) {
      session_.drag(ray);
    } else if (cursor.down) {
      camera_.orbit(-0.3 * (cursor.x - lastX_), 0.3 * (cursor.y - lastY_));
    } else if (mouseDown_ && session_.grabbing()) {
      session_.release();
    }
    mouseDown_ = cursor.down;
    lastX_ = cursor.x;
    lastY_ = cursor.y;
  }

  void panel() {
    const qv_model_info& info = model_.info();
    ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
    ImGui::SetNextWindowSize(ImVec2(430, 0), ImGuiCond_FirstUseEver);
    ImGui::Begin("quiver-view");
    ImGui::PushItemWidth(-170);  // room for the labels
    ImGui::Text("r = %d, %d vertices, %d tets", info.r, info.vertex_count, info.tet_count);
    ImGui::Text("%.0f steps/s; a step costs %.1f us (%.0f/s possible)", stepsPerSecond_, session_.stepMicros(),
                session_.stepMicros() > 0 ? 1e6 / session_.stepMicros() : 0.0);
    if (session_.behindRealTime()) ImGui::TextColored(ImVec4(1, 0.4f, 0.3f, 1), "slower than real time");
    if (session_.resets()) ImGui::TextColored(ImVec4(1, 0.4f, 0.3f, 1), "%d resets (non-finite, back to rest)", session_.resets());
    ImGui::Text("energy: kinetic %.3g J, elastic %.3g J", energies_.kinetic, energies_.elastic);
    const int shown = static_cast<int>(std::min<size_t>(energyFrames_, totalEnergy_.size()));  // a ring, oldest first
    ImGui::PlotLines("kinetic + elastic", totalEnergy_.data(), shown, static_cast<int>(energyFrames_ % totalEnergy_.size()), nullptr, 0,
                     FLT_MAX, ImVec2(0, 50));

    if (ImGui::CollapsingHeader("Simulation", ImGuiTreeNodeFlags_DefaultOpen)) {
      int integrator = edited_.step.integrator;
      if (ImGui::Combo("integrator", &integrator, integratorLabels_, QV_INTEGRATOR_COUNT))
        edited_.step.integrator = qv_integrator(integrator);
      int elasticity = edited_.step.elasticity;
      if (ImGui::Combo("elasticity", &elasticity, elasticityLabels_,
                       info.has_modal_rotations ? QV_ELASTICITY_COUNT : QV_ELASTICITY_MODAL_WARPING))
        edited_.step.elasticity = qv_elasticity(elasticity);
      double stepMs = 1000 * session_.config().time_step;
      if (ImGui::InputDouble("time step, ms", &stepMs, 0.5, 5, "%.3f", ImGuiInputTextFlags_EnterReturnsTrue) && stepMs > 0)
        edited_.step.timeStep = stepMs / 1000;
      if (edited_.step.integrator == QV_INTEGRATOR_CENTRAL_DIFFERENCES)
        ImGui::Text("stable below %.3f ms", 1000 * session_.stableTimeStep());
      else {
        int solver = edited_.step.solver;
        if (ImGui::Combo("solver", &solver, solverLabels_, QV_SOLVER_COUNT)) edited_.step.solver = qv_solver(solver);
        int newton = session_.config().newton_iterations;
        if (ImGui::SliderInt(edited_.step.solver == QV_SOLVER_MINIMIZE ? "most Newton iterations" : "Newton iterations",
                             &newton, 1, 20))
          edited_.step.newton = newton;
      }
      double alpha = session_.config().rayleigh_alpha, beta = session_.config().rayleigh_beta;
      if (ImGui::InputDouble("damping alpha, 1/s", &alpha, 0, 0, "%.4g", ImGuiInputTextFlags_EnterReturnsTrue))
        edited_.step.alpha = std::max(alpha, 0.0);
      if (ImGui::InputDouble("damping beta, s", &beta, 0, 0, "%.4g", ImGuiInputTextFlags_EnterReturnsTrue))
        edited_.step.beta = std::max(beta, 0.0);
      ImGui::Checkbox("gravity", &edited_.gravity);
      if (session_.flight()) {
        ImGui::Checkbox("soft contacts", &edited_.step.softContacts);
        int substeps = session_.config().max_substeps;
        if (ImGui::SliderInt("most substeps of a fast spin", &substeps, 1, 64)) edited_.step.maxSubsteps = substeps;
      }
      float spring = static_cast<float>(edited_.springStiffness);
      if (ImGui::SliderFloat("mouse spring, N/m", &spring, 1e-3f * spring + 1e-9f, 1e3f * spring, "%.3g",
                             ImGuiSliderFlags_Logarithmic))
        edited_.springStiffness = spring;
      if (ImGui::Button(session_.flight() ? "drop again (R)" : "reset (R)")) session_.reset();
      if (!(edited_ == session_.settings())) {
        try {
          session_.configure(edited_);
          settingsError_.clear();
        } catch (const std::exception& e) {
          settingsError_ = e.what();
        }
        edited_ = session_.settings();
      }
      if (!settingsError_.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.3f, 1), "%s", settingsError_.c_str());
    }

    if (!session_.flight() && ImGui::CollapsingHeader("Modes", ImGuiTreeNodeFlags_DefaultOpen)) {
      bool changed = ImGui::RadioButton("simulate", &modeKind_, 0);
      ImGui::SameLine();
      changed |= ImGui::RadioButton("linear modes", &modeKind_, 1);
      ImGui::SameLine();
      changed |= ImGui::RadioButton("basis vectors", &modeKind_, 2);
      if (modeKind_ != 0) {
        changed |= ImGui::SliderInt("index", &modeIndex_, 0, info.r - 1);
        changed |= ImGui::SliderFloat("amplitude", &modeAmplitude_, 0.01f, 0.5f, "%.2f of the size");
        if (modeKind_ == 1) {
          const double hz = std::sqrt(std::max(session_.modes().eigenvalues[modeIndex_], 0.0)) / (2 * M_PI);
          ImGui::Text("%.4g Hz in the reduced model", hz);
          if (modeIndex_ < info.eigenvalue_count)
            ImGui::Text("%.4g Hz baked (full mesh)", std::sqrt(std::max(qv_model_eigenvalues(model_.get())[modeIndex_], 0.0)) / (2 * M_PI));
        }
        ImGui::TextDisabled("shown at one oscillation per %.1f s", ViewSession::kModePeriod);
      }
      if (changed) session_.showMode(ModeKind(modeKind_), modeIndex_, modeAmplitude_ * size_);
    }
    ImGui::Checkbox("smooth normals (the runtime's)", &smoothNormals_);
    ImGui::TextDisabled(session_.flight() ? "left-drag an object: lift, drag, let go moving: throw\nleft-drag around it: orbit; wheel: zoom"
                                          : "left-drag the model: pull it\nleft-drag around it: orbit; wheel: zoom");
    ImGui::PopItemWidth();
    ImGui::End();
  }

  const ViewOptions& o_;
  const RuntimeModel& model_;
  ViewSession session_;
  ViewSettings edited_;
  const char* integratorLabels_[QV_INTEGRATOR_COUNT];  // the panel's menus, from the runtime's tables
  const char* elasticityLabels_[QV_ELASTICITY_COUNT];
  const char* solverLabels_[QV_SOLVER_COUNT];
  std::string settingsError_;
  std::vector<float> positions_, normals_, renderPositions_, renderNormals_;
  OrbitCamera camera_;
  TriangleSoup world_;  // the colliders' surfaces
  double size_;
  std::optional<DragScript> script_;
  bool mouseDown_ = false;
  double lastX_ = 0, lastY_ = 0;
  int grabs_ = 0;
  double stepsPerSecond_ = 0;
  ViewSession::Energies energies_{};
  std::array<float, 300> totalEnergy_{};  // the last 300 frames' total energy
  size_t energyFrames_ = 0;
  int modeKind_ = 0, modeIndex_ = 0;
  float modeAmplitude_ = 0.1f;
  bool smoothNormals_ = false;
};

} // namespace

} // namespace quiver::app

int main(int argc, char** argv) {
  using namespace quiver::app;
  CLI::App app{"quiver-view: simulate a baked model (.qvr) interactively"};
  ViewOptions o;
  app.add_option("model", o.model, "Model file (.qvr)")->required();
  app.add_option("--size", o.size, "Window width,height in pixels")->delimiter(',')->expected(2)->capture_default_str();
  addIntegratorOption(app, o.settings.step.integrator);
  addElasticityOption(app, o.settings.step.elasticity);
  addSolverOption(app, o.settings.step.solver);
  app.add_option("--dt", o.settings.step.timeStep, "Time step, s (default: the model's)")->check(TimeStep);
  app.add_option("--newton", o.settings.step.newton,
                 "Newton iterations per implicit step: the most (--solver minimize, default 8) or exactly (--solver newton)")
      ->check(CLI::Range(1, 20));
  app.add_flag("--gravity", o.settings.gravity, "Start with gravity, 9.81 m/s^2 along -z (always with --free)");
  app.add_flag("--free", o.settings.step.freeFlight,
               "Fly a free model (baked with no fixed vertex): it drops onto the colliders, by default a ground plane "
               "under it as baked, from one height above it");
  app.add_flag("--soft-contacts", o.settings.step.softContacts,
               "With --free: contacts hold the deformed surface, which gives way where they push (soft objects rest flat)");
  addMaxSubstepsOption(app, o.settings.step.maxSubsteps);
  o.flight.addTo(app);
  app.add_option("--frames", o.frames, "Run this many frames (1/60 s of simulation each), then exit")
      ->check(Positive);
  app.add_option("--screenshot", o.screenshot, "With --frames: save the last frame as a PNG");
  app.add_option("--drag-script", o.dragScript, "Drive the mouse from a script (apps/view/drag_script.h)");
  app.add_flag("--no-panel", o.noPanel, "Hide the control panel");
  app.add_flag("--gpu-skinning", o.gpuSkinning,
               "Draw the render mesh deformed in the vertex shader from its baked render basis, q uploaded each frame "
               "(as an engine would; shaded flat)");
  app.add_option("--show-mode", o.showMode, "Start in the mode browser: linear:N (a linear mode) or basis:N (a basis vector)");
  return runTool("quiver-view", app, argc, argv, [&] {
    if (o.size.size() != 2 || o.size[0] < 64 || o.size[1] < 64 || o.size[0] > 8192 || o.size[1] > 8192)
      throw std::runtime_error("--size must be two numbers between 64 and 8192");
    if (!o.screenshot.empty() && o.frames == 0) throw std::runtime_error("--screenshot needs --frames N");
    o.flight.check(o.settings.step.freeFlight);
    checkFlightSettings(o.settings.step);
    if (o.settings.step.freeFlight && !o.showMode.empty()) throw std::runtime_error("--show-mode shows a model in place: not with --free");
    if (o.settings.step.freeFlight) o.settings.gravity = true;
    const RuntimeModel model(o.model);
    Viewer viewer(o, model);
    return viewer.run();
  });
}
