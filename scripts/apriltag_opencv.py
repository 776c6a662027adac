"""OpenCV's AprilTag detector (cv2.aruco, DICT_APRILTAG_36h11) on the frames the
AprilTag bench writes, for the ratio against ours (issue 45).

    pip install opencv-contrib-python-headless
    cargo bench --bench apriltag            # writes target/apriltag/*.png
    python3 scripts/apriltag_opencv.py target/apriltag/*.png

Prints, per frame, the ids and corners OpenCV finds, the tag's pose by
solvePnP(SOLVEPNP_IPPE_SQUARE) through the bench's camera (f = 600 px, centre
(319.5, 239.5), tag 0.16 m; the truth is t = (0.1, 0, 1) m, 20° of yaw), and OpenCV's
median time per detection over 200 runs on one thread (cv2.setNumThreads(1)), grey
conversion excluded.
"""
import sys, time
import cv2
import numpy as np

K = np.array([[600.0, 0, 319.5], [0, 600.0, 239.5], [0, 0, 1]])
S = 0.16
# OpenCV's IPPE_SQUARE order: TL, TR, BR, BL with y up, as our tag frame.
OBJ = np.array([[-S / 2, S / 2, 0], [S / 2, S / 2, 0], [S / 2, -S / 2, 0], [-S / 2, -S / 2, 0]])

cv2.setNumThreads(1)
dictionary = cv2.aruco.getPredefinedDictionary(cv2.aruco.DICT_APRILTAG_36h11)
params = cv2.aruco.DetectorParameters()
params.cornerRefinementMethod = cv2.aruco.CORNER_REFINE_APRILTAG
detector = cv2.aruco.ArucoDetector(dictionary, params)
for path in sys.argv[1:]:
    grey = cv2.imread(path, cv2.IMREAD_GRAYSCALE)
    corners, ids, _ = detector.detectMarkers(grey)
    times = []
    for _ in range(200):
        t0 = time.perf_counter()
        detector.detectMarkers(grey)
        times.append(time.perf_counter() - t0)
    times.sort()
    found = [] if ids is None else ids.ravel().tolist()
    print(f"{path}: ids {found}, median {times[len(times) // 2] * 1e3:.2f} ms")
    for c in corners:
        img = c.reshape(-1, 2).astype(np.float64)
        print("   corners", [[round(float(v), 2) for v in p] for p in img])
        ok, rvec, tvec = cv2.solvePnP(OBJ, img, K, None, flags=cv2.SOLVEPNP_IPPE_SQUARE)
        if ok:
            yaw = np.degrees(np.arccos(np.clip(-cv2.Rodrigues(rvec)[0][2, 2], -1, 1)))
            print(f"   pose t = {np.round(tvec.ravel(), 4).tolist()} m, tilt {yaw:.2f} deg")
