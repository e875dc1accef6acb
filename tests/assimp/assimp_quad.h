/* assimp_quad.h — the Assimp tests' textured quad: an OBJ of one 2 x 1 quad with uv and material
 * "red" from quad.mtl, whose map_Kd is tex.ppm (2 x 1 texels: red, green). Include after
 * ../formats/test_util.h (PATHF, write_bytes, the check kit). */
#ifndef SY_TEST_ASSIMP_QUAD_H
#define SY_TEST_ASSIMP_QUAD_H

static const char assimp_quad_obj[] = "# quad\nmtllib quad.mtl\nv 0 0 0\nv 2 0 0\nv 2 1 0\nv 0 1 0\n"
                                      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl red\nf 1/1 2/2 3/3 4/4\n";
static const char assimp_quad_ppm[] = "P6\n2 1\n255\n\xff\x00\x00\x00\xff\x00";

/* Writes folder/quad.obj, folder/quad.mtl (the text mtl, which defines "red") and folder/tex.ppm,
 * each write an EXPECT; the OBJ's path into obj_path (cap bytes). */
static void write_assimp_quad(const char *folder, const char *mtl, char *obj_path, size_t cap)
{
    char path[4300];
    PATHF(path, "%s/quad.mtl", folder);
    EXPECT(write_bytes(path, mtl, strlen(mtl)) == 0);
    PATHF(path, "%s/tex.ppm", folder);
    EXPECT(write_bytes(path, assimp_quad_ppm, sizeof assimp_quad_ppm - 1) == 0);
    if (snprintf(obj_path, cap, "%s/quad.obj", folder) >= (int)cap) abort();
    EXPECT(write_bytes(obj_path, assimp_quad_obj, sizeof assimp_quad_obj - 1) == 0);
}

#endif /* SY_TEST_ASSIMP_QUAD_H */
