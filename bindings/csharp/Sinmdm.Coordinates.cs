// Coordinates for engines: poses from the model file's frame to Unity's (see Sinmdm.cs).
namespace Sinmdm
{
    /// <summary>From the model file's frame (right-handed, its up axis, its units) to Unity's
    /// (left-handed, Y-up, metres).</summary>
    public static class Coordinates
    {
        /// <summary>A position: turned so the file's up is +Y, X mirrored, scaled to metres
        /// (`metresPerUnit`: 0.01 for a file in centimetres).</summary>
        public static void ToUnityPosition(ModelInfo info, float[] xyz, int offset, float metresPerUnit)
        {
            float x = xyz[offset], y = xyz[offset + 1], z = xyz[offset + 2];
            if (info.UpZ > 0.5) { float t = y; y = z; z = -t; }  // Z-up: (x, y, z) -> (x, z, -y)
            xyz[offset] = -x * metresPerUnit;
            xyz[offset + 1] = y * metresPerUnit;
            xyz[offset + 2] = z * metresPerUnit;
        }

        /// <summary>A rotation x,y,z,w, turned the same way, then mirrored in X.</summary>
        public static void ToUnityRotation(ModelInfo info, float[] xyzw, int offset)
        {
            float x = xyzw[offset], y = xyzw[offset + 1], z = xyzw[offset + 2];
            if (info.UpZ > 0.5) { float t = y; y = z; z = -t; }
            xyzw[offset] = x;
            xyzw[offset + 1] = -y;
            xyzw[offset + 2] = -z;
        }
    }
}
