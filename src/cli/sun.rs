//! `sunshade sun`: where the sun is at a time and place (the daylight flags are `render::flags::daylight`).

use clap::Args;

use crate::render::flags::daylight::DaylightArgs;

/// `sunshade sun`: where the sun is at a time and place.
#[derive(Args, Debug)]
pub struct SunCommand {
    #[command(flatten)]
    pub daylight: DaylightArgs,

    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

pub fn run_sun(a: &SunCommand) -> Result<(), super::CliError> {
    let d = &a.daylight;
    d.check().map_err(super::CliError::Usage)?;
    let Some(at) = d.at_time() else {
        return Err(super::CliError::Usage("sunshade sun needs --time and --location".into()));
    };
    if a.json {
        println!("{}", serde_json::to_string_pretty(&at.json(d.north, d.linke_turbidity)).expect("JSON"));
        return Ok(());
    }
    let p = &at.position;
    let l = &at.location;
    let refraction = if p.refraction {
        let atm = d.atmosphere(l);
        format!("with refraction at {:.1} mbar, {:.1} °C", atm.pressure_mbar, atm.temperature_c)
    } else {
        "geometric, no refraction".into()
    };
    let v = at.direction;
    println!("time          {} (UT)", at.instant);
    println!("location      {:.6}°, {:.6}°, {} m", l.latitude_deg, l.longitude_deg, l.elevation_m);
    println!("zenith        {:.6}° ({refraction})", p.zenith_deg);
    println!("azimuth       {:.6}° (clockwise from north)", p.azimuth_deg);
    println!("elevation     {:.6}°: the sun is {}", p.elevation_deg(), if p.is_up() { "up" } else { "down" });
    println!("direction     {:.6}, {:.6}, {:.6} (scene axes, north at scene azimuth {}°)", v.x, v.y, v.z, d.north);
    println!("delta T       {:.2} s", p.delta_t_s);
    let c = &at.clear_sky;
    println!(
        "clear sky     DNI {:.1}, GHI {:.1}, DHI {:.1} W/m² (Ineichen-Perez, Linke turbidity {}); sky radiance {:.3} W/(m²·sr)",
        c.dni,
        c.ghi,
        c.dhi,
        d.linke_turbidity,
        c.sky_radiance()
    );
    Ok(())
}
