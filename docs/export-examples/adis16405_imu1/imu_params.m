% fogdrift export --target matlab: noise model for MATLAB imuSensor (gyroparams / accelparams, Navigation / Sensor Fusion Toolbox)
% from out/adis16405_imu1/allan.json (input SHA-256 a04609489001939e...)
% update rate 100.0 Hz; --missing bound
% gyro gx: allan model N+B+S+M (chi2_red 1.59, good)
% gyro gy: allan model N+B+K (chi2_red 1.55, good)
% gyro gz: allan no model fits; best candidate Q+N+B+K+S (chi2_red 6.12, poor)
% continuous -> discrete: white sigma_d = N sqrt(f), random-walk step sigma_bd = K / sqrt(f) (Kalibr wiki 'IMU Noise Model')
% Units per the gyroparams / accelparams reference pages: NoiseDensity (rad/s)/sqrt(Hz) and (m/s^2)/sqrt(Hz), RandomWalk (rad/s)*sqrt(Hz) and (m/s^2)*sqrt(Hz), BiasInstability rad/s and m/s^2
% (MathWorks Answers 1631045: RandomWalk is the rate random walk K, NoiseDensity the white density N)
% BiasInstability is B (the flicker floor); BiasInstabilityCoefficients is left at its default
% gx: N = 2.402 [2.374, 2.417] deg/sqrt(h) [resolved]; from allan fit: N (selected model N+B+S+M, fit good)
%   continuous 0.000698605 rad/s/sqrt(Hz) (the estimate; x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))); discrete 0.00698605 rad/s per sample at 100.0 Hz (x sqrt(f))
% gy: N = 2.521 [2.501, 2.537] deg/sqrt(h) [resolved]; from allan fit: N (selected model N+B+K, fit good)
%   continuous 0.000733391 rad/s/sqrt(Hz) (the estimate; x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))); discrete 0.00733391 rad/s per sample at 100.0 Hz (x sqrt(f))
% gz: N = 2.228 [2.157, 2.306] deg/sqrt(h) [no_fit]; from allan fit: N (selected model Q+N+B+K+S, fit poor)
%   continuous 0.000670925 rad/s/sqrt(Hz) (its 95 % upper bound (--missing bound); x 0.000290888 (deg/sqrt(h) -> rad/s/sqrt(Hz))); discrete 0.00670925 rad/s per sample at 100.0 Hz (x sqrt(f))
% written per axis (gx, gy, gz) in (rad/s)/sqrt(Hz)
% gx: K = < 207.7 deg/h^1.5 (95 % upper bound) [absent]; from allan fit: K (selected model N+B+S+M, fit good)
%   continuous 1.67801e-05 rad/s^2/sqrt(Hz) (its 95 % upper bound (--missing bound); x 8.08023e-08 (deg/h^1.5 -> rad/s^2/sqrt(Hz))); discrete 1.67801e-06 rad/s per-sample bias step at 100.0 Hz (/ sqrt(f))
% gy: K = 131.1 [0, 225.8] deg/h^1.5 [unresolved]; from allan fit: K (selected model N+B+K, fit good)
%   continuous 1.05932e-05 rad/s^2/sqrt(Hz) (the estimate; x 8.08023e-08 (deg/h^1.5 -> rad/s^2/sqrt(Hz))); discrete 1.05932e-06 rad/s per-sample bias step at 100.0 Hz (/ sqrt(f))
% gz: K = 191.1 [0, 362.2] deg/h^1.5 [no_fit]; from allan fit: K (selected model Q+N+B+K+S, fit poor)
%   continuous 2.9269e-05 rad/s^2/sqrt(Hz) (its 95 % upper bound (--missing bound); x 8.08023e-08 (deg/h^1.5 -> rad/s^2/sqrt(Hz))); discrete 2.9269e-06 rad/s per-sample bias step at 100.0 Hz (/ sqrt(f))
% written per axis (gx, gy, gz) in (rad/s)*sqrt(Hz)
% gx: B = 24.55 [12.99, 35.84] deg/h [resolved]; from allan fit: B (selected model N+B+S+M, fit good)
%   continuous 0.000119018 rad/s (the estimate; x 4.84814e-06 (deg/h -> rad/s)); a standard deviation: the same in continuous and discrete time
% gy: B = 36.31 [29.13, 43.75] deg/h [resolved]; from allan fit: B (selected model N+B+K, fit good)
%   continuous 0.000176056 rad/s (the estimate; x 4.84814e-06 (deg/h -> rad/s)); a standard deviation: the same in continuous and discrete time
% gz: B = 29.32 [0, 44.91] deg/h [no_fit]; from allan fit: B (selected model Q+N+B+K+S, fit poor)
%   continuous 0.000217742 rad/s (its 95 % upper bound (--missing bound); x 4.84814e-06 (deg/h -> rad/s)); a standard deviation: the same in continuous and discrete time
% written per axis (gx, gy, gz) in rad/s
gyro = gyroparams( ...
    'NoiseDensity', [0.000698605 0.000733391 0.000670925], ...     % (rad/s)/sqrt(Hz)
    'RandomWalk', [1.67801e-05 1.05932e-05 2.9269e-05], ...       % (rad/s)*sqrt(Hz)
    'BiasInstability', [0.000119018 0.000176056 0.000217742]);     % rad/s
% accelparams: not written: no accelerometer result was given (fogdrift export --accel RESULT.json); fogdrift never writes a noise figure it did not measure
imu = imuSensor('accel-gyro', 'SampleRate', 100.0, 'Gyroscope', gyro);
