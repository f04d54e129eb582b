% fogdrift export --target matlab: noise model for MATLAB imuSensor (gyroparams / accelparams, Navigation / Sensor Fusion Toolbox)
% from out/adis16405_imu1/allan.json (input SHA-256 a04609489001939e...)
% update rate 100.0 Hz; --missing bound
% gyro gx: allan model N+B+M (chi2_red 0.555, good)
% gyro gy: allan model N+B+K (chi2_red 0.329, good)
% gyro gz: allan model N+B+K (chi2_red 0.738, good)
% continuous -> discrete: white sigma_d = N sqrt(f), random-walk step sigma_bd = K / sqrt(f) (Kalibr wiki 'IMU Noise Model')
% Units per the gyroparams / accelparams reference pages: NoiseDensity (rad/s)/sqrt(Hz) and (m/s^2)/sqrt(Hz), RandomWalk (rad/s)*sqrt(Hz) and (m/s^2)*sqrt(Hz), BiasInstability rad/s and m/s^2
% (MathWorks Answers 1631045: RandomWalk is the rate random walk K, NoiseDensity the white density N)
% BiasInstability is B (the flicker floor); BiasInstabilityCoefficients is left at its default
% gx: N = 2.425 [2.308, 2.513] deg/sqrt(h) [resolved]; from allan fit: N (selected model N+B+M, fit good)
%   continuous 0.000705481 rad/s/sqrt(Hz) (the estimate; x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))); discrete 0.00705481 rad/s per sample at 100.0 Hz (x sqrt(f))
% gy: N = 2.539 [2.439, 2.613] deg/sqrt(h) [resolved]; from allan fit: N (selected model N+B+K, fit good)
%   continuous 0.000738681 rad/s/sqrt(Hz) (the estimate; x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))); discrete 0.00738681 rad/s per sample at 100.0 Hz (x sqrt(f))
% gz: N = 2.296 [2.188, 2.361] deg/sqrt(h) [resolved]; from allan fit: N (selected model N+B+K, fit good)
%   continuous 0.000667988 rad/s/sqrt(Hz) (the estimate; x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))); discrete 0.00667988 rad/s per sample at 100.0 Hz (x sqrt(f))
% written per axis (gx, gy, gz) in (rad/s)/sqrt(Hz)
% gx: K = < 198.6 deg/h^1.5 (95 % upper bound) [absent]; from allan fit: K (selected model N+B+M, fit good)
%   continuous 1.60508e-05 rad/s^2/sqrt(Hz) (its 95 % upper bound (--missing bound); x 8.08023e-08 (deg/h^1.5 -> rad/s^2/sqrt(Hz))); discrete 1.60508e-06 rad/s per-sample bias step at 100.0 Hz (/ sqrt(f))
% gy: K = 142.8 [0, 223.8] deg/h^1.5 [unresolved]; from allan fit: K (selected model N+B+K, fit good)
%   continuous 1.15401e-05 rad/s^2/sqrt(Hz) (the estimate; x 8.08023e-08 (deg/h^1.5 -> rad/s^2/sqrt(Hz))); discrete 1.15401e-06 rad/s per-sample bias step at 100.0 Hz (/ sqrt(f))
% gz: K = 207.5 [63.9, 293.3] deg/h^1.5 [resolved]; from allan fit: K (selected model N+B+K, fit good)
%   continuous 1.67685e-05 rad/s^2/sqrt(Hz) (the estimate; x 8.08023e-08 (deg/h^1.5 -> rad/s^2/sqrt(Hz))); discrete 1.67685e-06 rad/s per-sample bias step at 100.0 Hz (/ sqrt(f))
% written per axis (gx, gy, gz) in (rad/s)*sqrt(Hz)
% gx: B = 20.33 [0, 35.97] deg/h [unresolved]; from allan fit: B (selected model N+B+M, fit good)
%   continuous 9.85837e-05 rad/s (the estimate; x 4.84814e-06 (deg/h -> rad/s)); a standard deviation: the same in continuous and discrete time
% gy: B = 34.07 [25.99, 42.95] deg/h [resolved]; from allan fit: B (selected model N+B+K, fit good)
%   continuous 0.000165176 rad/s (the estimate; x 4.84814e-06 (deg/h -> rad/s)); a standard deviation: the same in continuous and discrete time
% gz: B = 25.53 [14.14, 35.16] deg/h [resolved]; from allan fit: B (selected model N+B+K, fit good)
%   continuous 0.000123752 rad/s (the estimate; x 4.84814e-06 (deg/h -> rad/s)); a standard deviation: the same in continuous and discrete time
% written per axis (gx, gy, gz) in rad/s
gyro = gyroparams( ...
    'NoiseDensity', [0.000705481 0.000738681 0.000667988], ...     % (rad/s)/sqrt(Hz)
    'RandomWalk', [1.60508e-05 1.15401e-05 1.67685e-05], ...       % (rad/s)*sqrt(Hz)
    'BiasInstability', [9.85837e-05 0.000165176 0.000123752]);     % rad/s
% accelparams: not written: no accelerometer result was given (fogdrift export --accel RESULT.json); matlab then uses its own ideal default
imu = imuSensor('accel-gyro', 'SampleRate', 100.0, 'Gyroscope', gyro);  % SampleRate [Hz]
