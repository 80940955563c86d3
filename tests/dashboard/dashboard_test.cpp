// The dashboard server: snapshots are validated, /metrics renders them in the Prometheus text format, /events
// streams the history then every new snapshot, and bad lines are counted without stopping anything.

#include "canyon/dashboard/dashboard.hpp"

#include <chrono>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <httplib.h>

namespace canyon::dashboard {
namespace {

const char* kSnapshot =
    R"({"t_s":12.5,"stages":{"ingest":{"p50_us":40,"p95_us":80,"p99_us":120,"max_us":300,"count":60}},)"
    R"("end_to_end":{"p50_us":150,"p95_us":400,"p99_us":900,"max_us":1500,"count":60},"correction_age_s":0.8,)"
    R"("queues":{"update":2},"drops":{"vio_decimated":3},"solution":{"seq":60,"status":1,"lat_deg":48.1,)"
    R"("lon_deg":11.5,"height_m":520.3,"n_sats":17,"pruned":["G05","E11"],"ratio":7.2},)"
    R"("alignment":{"rmse_m":0.04,"eigen_ratio":12.5,"lever_arm_m":[-0.1,0.05,0.0]}})";

TEST(DashboardSnapshot, ParsesAndRefusesBadLines) {
  EXPECT_TRUE(parse_snapshot(kSnapshot).ok());
  EXPECT_EQ(parse_snapshot("{not json").error().message.rfind("not JSON", 0), 0U);
  EXPECT_EQ(parse_snapshot("[1,2]").error().message.rfind("not a JSON object", 0), 0U);
  EXPECT_EQ(parse_snapshot(R"({"stages":{}})").error().message, "no number 't_s' in the snapshot");
  EXPECT_EQ(parse_snapshot(R"({"t_s":1,"solution":3})").error().message, "'solution' is not an object");
  // canyon monitor before the first solution, and in rtk mode (no alignment): null objects are left out.
  const auto early = parse_snapshot(R"({"t_s":1,"solution":null,"alignment":null,"queues":{}})");
  ASSERT_TRUE(early.ok()) << early.error().message;
  EXPECT_EQ(*early, R"({"queues":{},"t_s":1})");
}

TEST(DashboardSnapshot, PrometheusText) {
  const std::string text = prometheus_text(*parse_snapshot(kSnapshot), 5, 1);
  for (const char* line : {"canyon_dashboard_snapshots_total 5", "canyon_dashboard_bad_lines_total 1",
                           "canyon_stage_latency_us{stage=\"ingest\",quantile=\"0.99\"} 120",
                           "canyon_end_to_end_latency_us{quantile=\"0.5\"} 150", "canyon_correction_age_seconds 0.8",
                           "canyon_queue_depth{queue=\"update\"} 2", "canyon_drops_total{name=\"vio_decimated\"} 3",
                           "canyon_solution_status 1", "canyon_solution_pruned_satellites 2",
                           "canyon_lever_arm_m{axis=\"x\"} -0.1", "# TYPE canyon_drops_total counter"}) {
    EXPECT_NE(text.find(line), std::string::npos) << line << "\n" << text;
  }
  // Fields of the wrong type are left out, never a crash.
  const std::string odd = prometheus_text(R"({"t_s":1,"solution":{"status":"x","pruned":7}})", 1, 0);
  EXPECT_EQ(odd.find("\ncanyon_solution_status "), std::string::npos) << odd;
}

TEST(DashboardServer, ServesMetricsAndStreamsEvents) {
  ServerOptions options;
  options.port = 0;
  auto server = DashboardServer::start(options);
  ASSERT_TRUE(server.ok()) << server.error().to_string();
  ASSERT_TRUE((*server)->push(kSnapshot).ok());
  EXPECT_FALSE((*server)->push("garbage").ok());
  EXPECT_EQ((*server)->bad_lines(), 1U);

  httplib::Client client("127.0.0.1", (*server)->port());
  client.set_read_timeout(5, 0);
  auto metrics = client.Get("/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_EQ(metrics->status, 200);
  EXPECT_NE(metrics->body.find("canyon_solution_satellites 17"), std::string::npos);
  auto page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);

  // The stream: the history event first, then a snapshot pushed while the client listens.
  std::string received;
  std::thread pusher([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    (void)(*server)->push(R"({"t_s":13.5,"correction_age_s":1.1})");
  });
  httplib::Client sse("127.0.0.1", (*server)->port());
  sse.set_read_timeout(5, 0);
  auto res = sse.Get("/events", [&](const char* data, std::size_t n) {
    received.append(data, n);
    return received.find("data: {\"correction_age_s\":1.1") == std::string::npos;  // stop once it came
  });
  pusher.join();
  EXPECT_EQ(received.rfind("retry: 1000\nevent: history\ndata: [{", 0), 0U) << received;
  EXPECT_NE(received.find("\"t_s\":13.5"), std::string::npos) << received;
  (*server)->stop();
}

TEST(DashboardServer, RefusesBadOptions) {
  ServerOptions options;
  options.web_dir = "/nonexistent/web";
  auto s = DashboardServer::start(options);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("does not exist"), std::string::npos);
}

}  // namespace
}  // namespace canyon::dashboard
