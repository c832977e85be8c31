"""The operator "Denoise (rsmooth)" and the sidebar panel."""

import time
import warnings

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, StringProperty

DEVICES = [
    ("AUTO", "Auto", "The first OpenCL GPU, else the first OpenCL CPU device; the reference "
     "path (with a warning) where no OpenCL exists"),
    ("GPU", "GPU", "The first OpenCL GPU"),
    ("CPU", "CPU", "The first OpenCL CPU device (e.g. PoCL)"),
    ("REFERENCE", "Reference", "Double precision on one CPU thread, no OpenCL"),
    ("NAME", "By Name", "An OpenCL device by \"P:D\" (platform and device index) or part of its "
     "name"),
]

MODES = [
    ("PAPER", "Paper", "The paper's filter: one robust pass, sigma_f 2 and sigma_g 0.5 mean "
     "edge lengths"),
    ("BEST", "Best", "rsmooth's most accurate mode: the normal update stage, then one robust "
     "pass with bilateral normals at sigma_f 0.8, sigma_g 0.3 (slower)"),
]


def _import_rsmooth():
    """The vendored package (register() put _vendor/ first on sys.path), or an ImportError."""
    import rsmooth

    return rsmooth


def _meshes(context):
    """The selected mesh objects' meshes, each once: {mesh: [objects using it]}, in selection
    order."""
    meshes = {}
    for obj in context.selected_objects:
        if obj.type == "MESH":
            meshes.setdefault(obj.data, []).append(obj)
    return meshes


def _problem(mesh, objects):
    """Why this mesh cannot be changed, or None."""
    if mesh.library is not None:
        return "its mesh is linked from a library (make it local first)"
    if mesh.shape_keys is not None:
        return "it has shape keys (the filter would change only the base mesh): " \
               "apply or remove them first"
    if len(mesh.polygons) == 0:
        return "it has no faces"
    return None


def _arrays(mesh):
    """(vertices (n, 3) float32 in the object's local coordinates, triangles (m, 3) int32): the
    mesh's own data (modifiers not applied), its polygons split into Blender's loop triangles,
    the vertex order unchanged."""
    import numpy as np

    vertices = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", vertices)
    mesh.calc_loop_triangles()
    triangles = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", triangles)
    return vertices.reshape(-1, 3), triangles.reshape(-1, 3)


class OBJECT_OT_rsmooth_denoise(bpy.types.Operator):
    """Remove noise from the selected meshes and keep their sharp edges (rsmooth: Jones, Durand
    & Desbrun 2003)"""

    bl_idname = "object.rsmooth_denoise"
    bl_label = "Denoise (rsmooth)"
    bl_options = {"REGISTER", "UNDO"}

    mode: EnumProperty(name="Mode", items=MODES, default="PAPER")
    auto: BoolProperty(
        name="Auto",
        description="Estimate each mesh's noise and pick the widths from it (with Best, the "
        "normal update stage's strength too); a width set below still wins",
        default=False,
    )
    sigma_f: FloatProperty(
        name="Sigma F",
        description="Spatial width, in mean edge lengths: how far around a vertex triangles are "
        "consulted. 0: the mode's default (Paper 2, Best 0.8, or Auto's choice)",
        default=0.0, min=0.0, soft_max=8.0, step=10, precision=3,
    )
    sigma_g: FloatProperty(
        name="Sigma G",
        description="Influence width, in mean edge lengths: how far a triangle's plane may lie "
        "from a vertex before it counts as the other side of a sharp edge; larger smooths more. "
        "0: the mode's default (Paper 0.5, Best 0.3, or Auto's choice)",
        default=0.0, min=0.0, soft_max=4.0, step=5, precision=3,
    )
    device: EnumProperty(name="Device", items=DEVICES, default="AUTO")
    device_name: StringProperty(
        name="Device Name",
        description="With Device \"By Name\": \"P:D\" or part of an OpenCL device's name",
        default="",
    )

    @classmethod
    def poll(cls, context):
        if context.mode != "OBJECT":
            cls.poll_message_set("Works in Object Mode")
            return False
        if not any(obj.type == "MESH" for obj in context.selected_objects):
            cls.poll_message_set("Select one or more mesh objects")
            return False
        return True

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        layout.prop(self, "mode", expand=True)
        layout.prop(self, "auto")
        layout.prop(self, "sigma_f")
        layout.prop(self, "sigma_g")
        layout.prop(self, "device")
        if self.device == "NAME":
            layout.prop(self, "device_name")

    def _keywords(self):
        keywords = dict(best=self.mode == "BEST", auto=self.auto)
        if self.sigma_f > 0.0:
            keywords["sigma_f"] = self.sigma_f
        if self.sigma_g > 0.0:
            keywords["sigma_g"] = self.sigma_g
        if self.device == "NAME":
            keywords["device"] = self.device_name.strip() or "auto"
        else:
            keywords["device"] = self.device.lower()
        return keywords

    def execute(self, context):
        try:
            rsmooth = _import_rsmooth()
        except ImportError as e:
            self.report({"ERROR"}, f"rsmooth could not be loaded: {e}")
            return {"CANCELLED"}
        meshes = _meshes(context)
        keywords = self._keywords()
        wm = context.window_manager
        workspace = context.workspace
        results = []
        failed = False
        started = time.perf_counter()
        wm.progress_begin(0, len(meshes))
        try:
            for index, (mesh, objects) in enumerate(meshes.items()):
                name = objects[0].name if len(objects) == 1 else \
                    ", ".join(o.name for o in objects) + f" (mesh {mesh.name})"
                problem = _problem(mesh, objects)
                if problem is not None:
                    self.report({"ERROR"}, f"{name}: not denoised: {problem}")
                    failed = True
                    continue
                vertices, triangles = _arrays(mesh)

                def progress(fraction, index=index, name=name):
                    wm.progress_update(index + min(max(fraction, 0.0), 1.0))
                    if workspace is not None:
                        workspace.status_text_set(
                            f"rsmooth: {name}: {100.0 * fraction:.0f}% "
                            f"({index + 1} of {len(meshes)})")

                progress(0.0)
                try:
                    with warnings.catch_warnings(record=True) as caught:
                        warnings.simplefilter("always")
                        out = rsmooth.smooth(vertices, triangles, progress=progress, **keywords)
                except (ValueError, TypeError, RuntimeError, MemoryError) as e:
                    # rsmooth.DeviceError is a RuntimeError
                    kind = type(e).__name__
                    self.report({"ERROR"}, f"{name}: not denoised: {kind}: {e}")
                    failed = True
                    continue
                for w in caught:
                    self.report({"WARNING"}, f"{name}: {w.message}")
                results.append((mesh, name, out))
        finally:
            wm.progress_end()
            if workspace is not None:
                workspace.status_text_set(None)
        if failed:
            # all or nothing: one undo step, and a failure leaves every mesh as it was
            if results:
                self.report({"ERROR"}, "nothing changed: "
                            f"{len(results)} other mesh(es) were not written either")
            return {"CANCELLED"}
        for mesh, _, out in results:
            mesh.vertices.foreach_set("co", out.ravel())
            mesh.update()
        seconds = time.perf_counter() - started
        self.report({"INFO"}, f"rsmooth: {len(results)} mesh(es) denoised in {seconds:.2f} s "
                    f"({keywords['device']})")
        return {"FINISHED"}


class VIEW3D_PT_rsmooth(bpy.types.Panel):
    """The 3D View's sidebar tab: the operator, paper and best; its redo panel (bottom left)
    then has every option."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "rsmooth"
    bl_label = "Denoise (rsmooth)"
    bl_context = "objectmode"

    def draw(self, context):
        layout = self.layout
        col = layout.column(align=True)
        op = col.operator(OBJECT_OT_rsmooth_denoise.bl_idname, text="Denoise (Paper)")
        op.mode = "PAPER"
        op = col.operator(OBJECT_OT_rsmooth_denoise.bl_idname, text="Denoise (Best, Auto)")
        op.mode = "BEST"
        op.auto = True
        layout.label(text="Options: the Adjust Last Operation panel")


CLASSES = (OBJECT_OT_rsmooth_denoise, VIEW3D_PT_rsmooth)
