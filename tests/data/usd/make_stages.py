"""Writes the USD stages subd's USD reader is checked on, with Pixar's own USD (`usd-core`).

    python tests/data/usd/make_stages.py [DIR]      # default: this script's directory

Every attribute subd maps (see the README's USD section) appears at least once:

* ``meshes.usda`` (and the same layer as ``meshes.usdc`` and packaged as ``meshes.usdz``):
  ``/World`` (translate, rotateXYZ, scale) holds
  - ``Cage``: a Catmull-Clark cube with a semi-sharp crease chain (one sharpness per
    crease), an infinitely sharp corner, indexed face-varying UVs with seams, edge-and-corner
    boundaries (on a closed mesh: no effect) and ``cornersPlus1``;
  - ``Strip``: an open Loop strip, left-handed, with one sharpness per crease *edge*,
    vertex-interpolated UVs and edge-only boundaries;
  - ``Sub/Grid`` (``Sub`` has an ``orient`` and an inverted translate): a Catmull-Clark grid
    with a triangle, the smooth triangle rule, unindexed face-varying UVs, ``boundaries``,
    a hole, and points with time samples besides their default;
  - ``Flat``: a ``none`` (polygonal) mesh, ``!resetXformStack!`` in its ops.
* ``composed.usda``: a reference whose variant set picks the mesh (``part.usda``), and a
  sublayer (``base.usda``) whose opinion sets the referenced mesh's boundary rule.

The committed files are this script's output; the tests regenerate nothing.
"""

import math
import os
import sys

from pxr import Gf, Sdf, Usd, UsdGeom, UsdUtils, Vt


def cube(mesh: UsdGeom.Mesh) -> None:
    mesh.CreatePointsAttr([(-1, -1, 1), (1, -1, 1), (-1, 1, 1), (1, 1, 1),
                           (-1, 1, -1), (1, 1, -1), (-1, -1, -1), (1, -1, -1)])
    mesh.CreateFaceVertexCountsAttr([4] * 6)
    mesh.CreateFaceVertexIndicesAttr([0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6,
                                      6, 7, 1, 0, 1, 7, 5, 3, 6, 0, 2, 4])
    mesh.CreateSubdivisionSchemeAttr("catmullClark")
    mesh.CreateInterpolateBoundaryAttr("edgeAndCorner")
    mesh.CreateFaceVaryingLinearInterpolationAttr("cornersPlus1")
    # One chain of 4 edges around the top face, one sharpness for the whole crease.
    mesh.CreateCreaseIndicesAttr([0, 1, 3, 2, 0])
    mesh.CreateCreaseLengthsAttr([5])
    mesh.CreateCreaseSharpnessesAttr([2.5])
    mesh.CreateCornerIndicesAttr([4])
    mesh.CreateCornerSharpnessesAttr([10.0])
    # A cross layout: 14 values, seams where the cross is cut.
    st = [(0.375, 0), (0.625, 0), (0.375, 0.25), (0.625, 0.25), (0.375, 0.5), (0.625, 0.5),
          (0.375, 0.75), (0.625, 0.75), (0.375, 1), (0.625, 1), (0.875, 0), (0.875, 0.25),
          (0.125, 0), (0.125, 0.25)]
    idx = [0, 1, 3, 2, 2, 3, 5, 4, 4, 5, 7, 6, 6, 7, 9, 8, 1, 10, 11, 3, 12, 0, 2, 13]
    pv = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                                 UsdGeom.Tokens.faceVarying)
    pv.Set(st)
    pv.SetIndices(Vt.IntArray(idx))


def strip(mesh: UsdGeom.Mesh) -> None:
    # 2 x 3 vertices, 4 triangles.
    pts = [(x, y, 0.1 * x * y) for y in range(2) for x in range(3)]
    mesh.CreatePointsAttr(pts)
    mesh.CreateFaceVertexCountsAttr([3, 3, 3, 3])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4])
    mesh.CreateOrientationAttr(UsdGeom.Tokens.leftHanded)
    mesh.CreateSubdivisionSchemeAttr("loop")
    mesh.CreateInterpolateBoundaryAttr("edgeOnly")
    # One crease of 2 interior edges, a sharpness per edge.
    mesh.CreateCreaseIndicesAttr([0, 4, 1])
    mesh.CreateCreaseLengthsAttr([3])
    mesh.CreateCreaseSharpnessesAttr([1.5, 3.25])
    pv = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                                 UsdGeom.Tokens.vertex)
    pv.Set([(p[0] / 2.0, p[1]) for p in pts])


def grid(mesh: UsdGeom.Mesh) -> None:
    n = 4
    pts = [(x, y, 0.05 * (x - 1.5) ** 2) for y in range(n) for x in range(n)]
    counts, idx = [], []
    for y in range(n - 1):
        for x in range(n - 1):
            v = y * n + x
            if (x, y) == (2, 2):
                # Split the last quad into two triangles.
                counts += [3, 3]
                idx += [v, v + 1, v + n + 1, v, v + n + 1, v + n]
            else:
                counts.append(4)
                idx += [v, v + 1, v + n + 1, v + n]
    mesh.CreatePointsAttr(pts)
    moved = [(p[0], p[1], p[2] + 1.0) for p in pts]
    points = mesh.GetPointsAttr()
    points.Set(pts, Usd.TimeCode(0))
    points.Set(moved, Usd.TimeCode(10))
    mesh.CreateFaceVertexCountsAttr(counts)
    mesh.CreateFaceVertexIndicesAttr(idx)
    mesh.CreateSubdivisionSchemeAttr("catmullClark")
    mesh.CreateTriangleSubdivisionRuleAttr("smooth")
    mesh.CreateFaceVaryingLinearInterpolationAttr("boundaries")
    mesh.CreateHoleIndicesAttr([0])
    # Unindexed face-varying values: one per corner, each face its own UV island.
    st = [(pts[v][0] / 3.0 + 0.01 * f, pts[v][1] / 3.0)
          for f, v in zip(face_of_corner(counts), idx)]
    pv = UsdGeom.PrimvarsAPI(mesh).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray,
                                                 UsdGeom.Tokens.faceVarying)
    pv.Set(st)


def face_of_corner(counts):
    return [f for f, c in enumerate(counts) for _ in range(c)]


def flat(mesh: UsdGeom.Mesh) -> None:
    mesh.CreatePointsAttr([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (2, 0.5, 0)])
    mesh.CreateFaceVertexCountsAttr([4, 3])
    mesh.CreateFaceVertexIndicesAttr([0, 1, 2, 3, 1, 4, 2])
    mesh.CreateSubdivisionSchemeAttr("none")


def meshes(path: str) -> Usd.Stage:
    stage = Usd.Stage.CreateNew(path)
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.z)
    UsdGeom.SetStageMetersPerUnit(stage, 0.01)
    world = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(world.GetPrim())
    world.AddTranslateOp().Set(Gf.Vec3d(10, -2, 0.5))
    world.AddRotateXYZOp().Set(Gf.Vec3f(30, 15, 60))
    world.AddScaleOp().Set(Gf.Vec3f(2, 2, 3))
    cube(UsdGeom.Mesh.Define(stage, "/World/Cage"))
    strip(UsdGeom.Mesh.Define(stage, "/World/Strip"))
    sub = UsdGeom.Xform.Define(stage, "/World/Sub")
    q = Gf.Quatf(math.cos(0.3), Gf.Vec3f(0, math.sin(0.3), 0))
    sub.AddOrientOp().Set(q)
    sub.AddTranslateOp(opSuffix="pivot").Set(Gf.Vec3d(1, 2, 3))
    sub.AddTranslateOp(opSuffix="pivot", isInverseOp=True)
    sub.AddRotateZOp().Set(45.0)
    grid(UsdGeom.Mesh.Define(stage, "/World/Sub/Grid"))
    flat_mesh = UsdGeom.Mesh.Define(stage, "/World/Flat")
    flat(flat_mesh)
    flat_mesh.SetResetXformStack(True)
    flat_mesh.AddTranslateOp().Set(Gf.Vec3d(0, 0, 7))
    return stage


def composed(dir_: str) -> None:
    part = Usd.Stage.CreateNew(os.path.join(dir_, "part.usda"))
    root = UsdGeom.Xform.Define(part, "/Part")
    part.SetDefaultPrim(root.GetPrim())
    vset = root.GetPrim().GetVariantSets().AddVariantSet("shape")
    for name, scheme in [("smooth", "catmullClark"), ("tri", "loop")]:
        vset.AddVariant(name)
        vset.SetVariantSelection(name)
        with vset.GetVariantEditContext():
            m = UsdGeom.Mesh.Define(part, "/Part/Body")
            if scheme == "loop":
                strip(m)
            else:
                cube(m)
    vset.SetVariantSelection("smooth")
    part.GetRootLayer().Save()
    # The sublayer's opinion (weaker than the root layer's, stronger than the reference's)
    # changes the referenced mesh's boundary rule.
    base = Usd.Stage.CreateNew(os.path.join(dir_, "base.usda"))
    body = base.OverridePrim("/Asset/Body")
    body.CreateAttribute("interpolateBoundary", Sdf.ValueTypeNames.Token).Set("none")
    base.GetRootLayer().Save()
    stage = Usd.Stage.CreateNew(os.path.join(dir_, "composed.usda"))
    stage.GetRootLayer().subLayerPaths.append("base.usda")
    asset = UsdGeom.Xform.Define(stage, "/Asset")
    asset.AddTranslateOp().Set(Gf.Vec3d(0, 5, 0))
    asset.GetPrim().GetReferences().AddReference("part.usda")
    asset.GetPrim().GetVariantSets().GetVariantSet("shape").SetVariantSelection("tri")
    stage.SetDefaultPrim(asset.GetPrim())
    stage.GetRootLayer().Save()


def main() -> None:
    dir_ = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    stage = meshes(os.path.join(dir_, "meshes.usda"))
    stage.GetRootLayer().Save()
    stage.GetRootLayer().Export(os.path.join(dir_, "meshes.usdc"))
    UsdUtils.CreateNewUsdzPackage(Sdf.AssetPath(os.path.join(dir_, "meshes.usdc")),
                                  os.path.join(dir_, "meshes.usdz"))
    composed(dir_)


if __name__ == "__main__":
    main()
